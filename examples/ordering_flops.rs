//! Flops and factor sizes of METIS nested dissections of the benchmark lattices' node graphs
//! under several METIS options (analysis only: no factorization), with METIS's wall time.
//!
//! `cargo run --release --example ordering_flops -- 40x40x40 27x27x27 [seed=1 seed=2 ufactor=50 ...]`
//! Cells as `NXxNYxNZ`; options as `seed=S`, `ufactor=U` or `seed=S,ufactor=U`; without
//! options: METIS's defaults and the tree path's second ordering. The defaults come first.
//! With `analyze=K`, each lattice is also analysed K times as `linkage run` does
//! (`SparseCholesky::analyze_with`), printing the time, the kept ordering and a hash of the
//! DOF permutation (the same on every repetition if the analysis is repeatable).
//! With `split`, also the alternative to two orderings side by side: one top separator
//! (`METIS_ComputeVertexSeparator`), then its two sides ordered by METIS side by side, the
//! separator last; and the wall time of the two side-by-side orderings the tree path runs.

use anyhow::{bail, Context, Result};
use linkage::bench::cholmod::lattice_system;
use linkage::linalg::ordering::{
    best_of_two_orderings, factor_cost, graph_of_pattern, nested_dissection,
    nested_dissection_with, MetisOptions, SECOND_ORDERING,
};
use linkage::linalg::SparseCholesky;
use std::hash::{Hash, Hasher};
use std::time::Instant;

fn parse_options(arg: &str) -> Result<MetisOptions> {
    let mut o = MetisOptions::default();
    for part in arg.split(',') {
        let (key, value) = part
            .split_once('=')
            .with_context(|| format!("option {part:?}: expected key=value"))?;
        let v: i32 = value
            .parse()
            .with_context(|| format!("option {part:?}: not an integer"))?;
        match key {
            "seed" => o.seed = Some(v),
            "ufactor" => o.ufactor = Some(v),
            _ => bail!("option {part:?}: expected seed or ufactor"),
        }
    }
    Ok(o)
}

fn parse_cells(arg: &str) -> Result<[usize; 3]> {
    let v: Vec<usize> = arg
        .split('x')
        .map(|p| p.parse().with_context(|| format!("cells {arg:?}")))
        .collect::<Result<_>>()?;
    v.try_into()
        .map_err(|_| anyhow::anyhow!("cells {arg:?}: expected NXxNYxNZ"))
}

fn main() -> Result<()> {
    let (mut cells, mut options) = (Vec::new(), vec![MetisOptions::default()]);
    let (mut analyses, mut split) = (0, false);
    for arg in std::env::args().skip(1) {
        if arg == "split" {
            split = true;
        } else if let Some(k) = arg.strip_prefix("analyze=") {
            analyses = k.parse().with_context(|| format!("{arg:?}"))?;
        } else if arg.contains('=') {
            options.push(parse_options(&arg)?);
        } else {
            cells.push(parse_cells(&arg)?);
        }
    }
    if options.len() == 1 {
        options.push(SECOND_ORDERING);
    }
    for c in cells {
        let (s, _) = lattice_system(c).map_err(anyhow::Error::msg)?;
        let groups = s.groups.as_deref().context("lattice without node groups")?;
        let n_nodes = groups.iter().max().map_or(0, |&m| m + 1);
        let (x, a) = graph_of_pattern(s.n, &s.col_ptr, &s.row_idx, Some(groups), n_nodes)?;
        let mut sizes = vec![0usize; n_nodes];
        groups.iter().for_each(|&node| sizes[node] += 1);
        let mut base = None;
        for &o in &options {
            let t = Instant::now();
            let (perm, inv) = nested_dissection_with(&x, &a, o)?;
            let metis = t.elapsed().as_secs_f64();
            let cost = factor_cost(&x, &a, &perm, &inv, &sizes);
            let base_flops = *base.get_or_insert(cost.flops);
            println!(
                "{}x{}x{} ({} DOFs): {o}: {:.4e} flops ({:+.2}%), nnz(L) {}, METIS {metis:.2} s",
                c[0],
                c[1],
                c[2],
                s.n,
                cost.flops,
                100.0 * (cost.flops / base_flops - 1.0),
                cost.entries
            );
        }
        if split {
            let name = format!("{}x{}x{}", c[0], c[1], c[2]);
            let t = Instant::now();
            let (perm, inv) = separator_then_halves(&x, &a)?;
            let time = t.elapsed().as_secs_f64();
            let cost = factor_cost(&x, &a, &perm, &inv, &sizes);
            println!(
                "{name}: top separator, then its sides side by side: {:.4e} flops, nnz(L) {}, {time:.2} s",
                cost.flops, cost.entries
            );
            let t = Instant::now();
            let two = best_of_two_orderings(&x, &a, &sizes, SECOND_ORDERING)?;
            println!(
                "{name}: two orderings side by side (with their flops): {:.2} s, kept {:.4e}",
                t.elapsed().as_secs_f64(),
                two.cost.flops
            );
        }
        for k in 1..=analyses {
            let t = Instant::now();
            let chol = SparseCholesky::analyze_with(
                s.n,
                &s.col_ptr,
                &s.row_idx,
                Some(groups),
                Default::default(),
            )?;
            let time = t.elapsed().as_secs_f64();
            let mut h = std::collections::hash_map::DefaultHasher::new();
            chol.permutation().hash(&mut h);
            let kept = chol.ordering_choice().map_or("-".to_string(), |o| {
                format!(
                    "{} kept, {:.4e} flops against {:.4e}",
                    if o.second_chosen {
                        SECOND_ORDERING
                    } else {
                        MetisOptions::default()
                    },
                    o.chosen.flops,
                    o.other.flops
                )
            });
            println!(
                "{}x{}x{}: analysis {k}: {time:.3} s, {kept}, perm hash {:016x}",
                c[0],
                c[1],
                c[2],
                h.finish()
            );
        }
    }
    Ok(())
}

/// One METIS vertex separator of the whole graph, then each side ordered by METIS (side by
/// side, one thread each), the separator last: `(perm, inv)`.
fn separator_then_halves(xadj: &[usize], adjncy: &[usize]) -> Result<(Vec<usize>, Vec<usize>)> {
    use metis_sys::idx_t;
    let n = xadj.len() - 1;
    let mut mx: Vec<idx_t> = xadj
        .iter()
        .map(|&v| idx_t::try_from(v))
        .collect::<Result<_, _>>()?;
    let mut ma: Vec<idx_t> = adjncy
        .iter()
        .map(|&v| idx_t::try_from(v))
        .collect::<Result<_, _>>()?;
    let mut nvtxs = idx_t::try_from(n)?;
    let mut sepsize: idx_t = 0;
    let mut part: Vec<idx_t> = vec![0; n];
    // SAFETY: the graph comes from `graph_of_pattern` (symmetric, no self loops, indices in
    // range); `part` holds n entries; null weights and options select METIS's defaults.
    let status = unsafe {
        metis_sys::METIS_ComputeVertexSeparator(
            &mut nvtxs,
            mx.as_mut_ptr(),
            ma.as_mut_ptr(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            &mut sepsize,
            part.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        bail!("METIS_ComputeVertexSeparator failed with status {status}");
    }
    // The subgraph induced by each side, renumbered.
    let side = |p: idx_t| {
        let verts: Vec<usize> = (0..n).filter(|&v| part[v] == p).collect();
        let mut local = vec![usize::MAX; n];
        verts.iter().enumerate().for_each(|(i, &v)| local[v] = i);
        let mut sx = vec![0];
        let mut sa = Vec::new();
        for &v in &verts {
            sa.extend(
                adjncy[xadj[v]..xadj[v + 1]]
                    .iter()
                    .map(|&u| local[u])
                    .filter(|&u| u != usize::MAX),
            );
            sx.push(sa.len());
        }
        (verts, sx, sa)
    };
    let (s0, s1) = (side(0), side(1));
    let order = |(verts, sx, sa): &(Vec<usize>, Vec<usize>, Vec<usize>)| {
        nested_dissection(sx, sa).map(|(p, _)| p.iter().map(|&i| verts[i]).collect::<Vec<_>>())
    };
    let (p0, p1) = rayon::join(|| order(&s0), || order(&s1));
    let perm: Vec<usize> = p0?
        .into_iter()
        .chain(p1?)
        .chain((0..n).filter(|&v| part[v] == 2))
        .collect();
    let mut inv = vec![0; n];
    perm.iter()
        .enumerate()
        .for_each(|(new, &old)| inv[old] = new);
    Ok((perm, inv))
}
