//! Flops and factor sizes of METIS nested dissections of the benchmark lattices' node graphs
//! under several METIS options (analysis only: no factorization), with METIS's wall time.
//!
//! `cargo run --release --example ordering_flops -- 40x40x40 27x27x27 [seed=1 seed=2 ufactor=50 ...]`
//! Cells as `NXxNYxNZ`; options as `seed=S`, `ufactor=U` or `seed=S,ufactor=U`; without
//! options: METIS's defaults and the tree path's second ordering. The defaults come first.
//! With `analyze=K`, each lattice is also analysed K times as `linkage run` does
//! (`SparseCholesky::analyze_with`), printing the time, the kept ordering and a hash of the
//! DOF permutation (the same on every repetition if the analysis is repeatable).

use anyhow::{bail, Context, Result};
use linkage::bench::cholmod::lattice_system;
use linkage::linalg::ordering::{
    factor_cost, graph_of_pattern, nested_dissection_with, MetisOptions, SECOND_ORDERING,
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
    let mut analyses = 0;
    for arg in std::env::args().skip(1) {
        if let Some(k) = arg.strip_prefix("analyze=") {
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
