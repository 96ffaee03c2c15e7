//! `linkage bench --fracture`: breaking members one after another in a large 3D lattice, with
//! the factorization kept and corrected (Woodbury) against refactoring at every break.

use crate::bench::lattice::peak_memory;
use crate::linkage::fracture::{BreakingEquilibrium, MemberLimits};
use crate::linkage::generators::box_lattice;
use crate::linkage::{Body, Material, Schedule, Support};
use crate::Real;
use nalgebra::Vector3;
use std::time::Instant;

/// What one fracture benchmark measured.
#[derive(Clone, Debug)]
pub struct FractureTiming {
    /// Lattice cells.
    pub cells: [usize; 3],
    /// Nodes and members of the lattice.
    pub nodes: usize,
    /// Members of the lattice.
    pub members: usize,
    /// Rows of `K_ff`.
    pub free_dofs: usize,
    /// Ordering and symbolic factorization, s.
    pub symbolic_seconds: Real,
    /// One numeric factorization of the intact lattice, s.
    pub factor_seconds: Real,
    /// The mean numeric factorization of the run (the first and every refactorization, timed
    /// under the same load as the breaks), s: what "factorizations' worth" is counted in.
    pub mean_factor_seconds: Real,
    /// One solve (forward and back substitution) with it, s.
    pub solve_seconds: Real,
    /// Breaks made with the factor kept.
    pub breaks: usize,
    /// Their total time, s.
    pub breaking_seconds: Real,
    /// Refactorizations among them (every `refactor_every` breaks, and when pieces fell off).
    pub refactorizations: usize,
    /// Breaks between refactorizations.
    pub refactor_every: usize,
    /// Breaks made refactoring at every break (the comparison).
    pub compared_breaks: usize,
    /// Their time per break, s.
    pub refactor_seconds_per_break: Real,
    /// Whether both ways broke the same members in the same order, at load fractions equal
    /// to 1e-9.
    pub same_sequence: bool,
    /// Of the breaks' time: solves and Woodbury corrections (the removals and the load
    /// pattern's re-solve after each refactorization), s.
    pub break_solve_seconds: Real,
    /// Of the breaks' time: refactorizations (numeric), s.
    pub refactor_numeric_seconds: Real,
    /// Of the solves, when breaks are taken in the factor's space: the sparse forward solves
    /// and the backward solves, s.
    pub factor_space_seconds: Option<(Real, Real)>,
    /// Peak resident memory of the process, bytes.
    pub peak_memory: u64,
}

/// A strength factor in [1, 3) per member from a fixed integer hash (SplitMix64), the same on
/// every machine.
fn scatter(m: usize) -> Real {
    let mut z = (m as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    1.0 + 2.0 * (z >> 11) as Real / (1u64 << 53) as Real
}

/// A steel lattice of `cells` cells of 1 cm (members of 1 mm²), bottom face clamped, top face
/// pulled up 0.5 % of the height; each member breaks in tension at 400 MPa times a factor in
/// [1, 3) (so about a third of the vertical members would break at the full pull, far more
/// than measured).
pub fn fracture_lattice(cells: [usize; 3]) -> Result<(Body, MemberLimits), String> {
    let h = 0.01;
    let size = cells.map(|c| c as Real * h);
    let geometry = box_lattice(size, cells).map_err(|e| e.to_string())?;
    let mut body = Body::from_geometry("lattice", geometry, Material::new("steel", 200e9, 1e-6));
    for i in 0..body.nodes.len() {
        let z = body.nodes[i].z;
        if z.abs() < 1e-9 {
            body.supports.push(Support::fixed(i, [true; 3]));
        } else if (z - size[2]).abs() < 1e-9 {
            body.supports.push(Support {
                node: i,
                fixed: [true; 3],
                displacement: Vector3::new(0.0, 0.0, 0.005 * size[2]),
                schedule: Schedule::Linear,
            });
        }
    }
    let limits = (0..body.members.len())
        .map(|m| Some((400e6 * scatter(m), Real::INFINITY)))
        .collect();
    Ok((body, limits))
}

/// Break `breaks` members of the lattice of `cells` one by one (one load step), keeping the
/// factor; then break the first `compare` of them again refactoring at every break.
pub fn measure_fracture(
    cells: [usize; 3],
    breaks: usize,
    compare: usize,
) -> Result<FractureTiming, String> {
    let (body, limits) = fracture_lattice(cells)?;
    let mut eq =
        BreakingEquilibrium::with_limits(&body, limits.clone()).map_err(|e| e.to_string())?;
    let (symbolic, factor, solve) = (eq.times.symbolic, eq.times.numeric, eq.times.solve);
    let mut fallen = Vec::new();
    let t = Instant::now();
    let mut events = Vec::with_capacity(breaks);
    while events.len() < breaks {
        match eq.next_event(&body, 1, 1, &mut fallen) {
            Ok(e) if e.is_empty() => break,
            Ok(e) => events.extend(e),
            Err(e) => return Err(format!("after {} breaks: {e}", events.len())),
        }
    }
    let breaking = t.elapsed().as_secs_f64();
    let break_solve = eq.times.solve - solve;
    let refactor_numeric = eq.times.numeric - factor;
    let factor_space = eq.factor_space_seconds();
    let mean_factor = eq.times.numeric / eq.factorizations.max(1) as Real;
    let refactorizations = eq.factorizations - 1;
    let refactor_every = eq.refactor_every;
    let free_dofs = eq.assembly.n;
    drop(eq);
    let mut slow = BreakingEquilibrium::with_limits(&body, limits).map_err(|e| e.to_string())?;
    slow.refactor_every = 1;
    let t = Instant::now();
    let mut same = true;
    let compared = compare.min(events.len());
    let mut checked = 0;
    while checked < compared {
        match slow.next_event(&body, 1, 1, &mut fallen) {
            Ok(group) if !group.is_empty() => {
                for e in group {
                    if let Some(expected) = events.get(checked) {
                        same &= e.member == expected.member
                            && (e.fraction - expected.fraction).abs()
                                <= 1e-9 * expected.fraction.abs().max(1e-300);
                    }
                    checked += 1;
                }
            }
            _ => {
                same = false;
                break;
            }
        }
    }
    let refactor_per_break = t.elapsed().as_secs_f64() / compared.max(1) as Real;
    Ok(FractureTiming {
        cells,
        nodes: body.nodes.len(),
        members: body.members.len(),
        free_dofs,
        symbolic_seconds: symbolic,
        factor_seconds: factor,
        mean_factor_seconds: mean_factor,
        solve_seconds: solve,
        breaks: events.len(),
        breaking_seconds: breaking,
        refactorizations,
        refactor_every,
        compared_breaks: compared,
        refactor_seconds_per_break: refactor_per_break,
        same_sequence: same,
        break_solve_seconds: break_solve,
        refactor_numeric_seconds: refactor_numeric,
        factor_space_seconds: factor_space,
        peak_memory: peak_memory(),
    })
}

/// The solves of one break in the factor's space against a full solve with the same factor,
/// timed side by side (the least of the repetitions, alternating: the least disturbed by
/// other work on the machine), s.
#[derive(Clone, Debug)]
pub struct SolveSplit {
    /// Entries of the factor's values (faer's supernodal storage).
    pub factor_values: usize,
    /// Rows of the sparse forward solve's result (of n).
    pub reach_rows: usize,
    /// A full solve (faer: forward and backward).
    pub full: Real,
    /// The sparse forward solve of one member's six entries.
    pub forward_sparse: Real,
    /// One backward solve, subtrees side by side.
    pub backward: Real,
    /// One backward solve on one thread.
    pub backward_one_thread: Real,
    /// faer's backward solve (`l_transpose_solve`, one thread), for comparison; infinite
    /// where the factor has the node graph's structure, which faer's solve cannot read.
    pub faer_backward: Real,
}

/// Time [`SolveSplit`] on the intact lattice of `cells`, `reps` times each.
pub fn measure_solve_split(cells: [usize; 3], reps: usize) -> Result<SolveSplit, String> {
    use crate::linalg::tree_solve::{ReachWork, SupernodalSolver};
    use crate::linalg::SparseCholesky;
    use crate::linkage::{linear_member_block, DofMap, StiffnessAssembly};
    let (body, _) = fracture_lattice(cells)?;
    let dofs = DofMap::new(&body);
    let asm = StiffnessAssembly::new(&body, &dofs).map_err(|e| e.to_string())?;
    let mut values = Vec::new();
    asm.fill(&body, |m| linear_member_block(&body, m), &mut values);
    let mut chol = SparseCholesky::analyze(asm.n, &asm.col_ptr, &asm.row_idx, Some(&asm.groups))
        .map_err(|e| e.to_string())?;
    chol.factorize(&values).map_err(|e| e.to_string())?;
    let solver = SupernodalSolver::new(&chol).ok_or("the factor is not supernodal and large")?;
    let n = asm.n;
    // A member in the middle of the lattice: its nodes' free DOFs, unit axis along x.
    let m = body.members.len() / 2;
    let mut g = Vec::new();
    for (sign, &node) in [-1.0, 1.0].iter().zip(&body.members[m].nodes) {
        for dir in 0..3 {
            if let Some(i) = dofs.free_index(node, dir) {
                g.push((i, sign * if dir == 0 { 1.0 } else { 0.5 }));
            }
        }
    }
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| e.to_string())?;
    let mut work = ReachWork::default();
    let mut x = vec![0.0; n];
    let mut rhs = vec![0.0; n];
    let inf = Real::INFINITY;
    let (mut full, mut fwd, mut bwd, mut bwd1, mut reach) = (inf, inf, inf, inf, 0);
    let mut fb = inf;
    // faer's backward solve reads only faer's own structure (not the node graph's of the
    // tree path): timed where there is one.
    let mut mem = chol.supernodal_symbolic().map(|sym| {
        faer::dyn_stack::MemBuffer::new(sym.solve_in_place_scratch::<f64>(1, faer::Par::Seq))
    });
    for _ in 0..reps.max(1) {
        rhs.fill(1.0);
        let t = Instant::now();
        chol.solve_in_place(&mut rhs);
        full = full.min(t.elapsed().as_secs_f64());
        let l = chol.factor_values().ok_or("not factored")?;
        x.fill(0.0);
        let t = Instant::now();
        let z = solver.forward_sparse(l, &g, &mut x, &mut work);
        fwd = fwd.min(t.elapsed().as_secs_f64());
        reach = z.rows.len();
        let mut y = x.clone();
        let t = Instant::now();
        solver.backward(l, &mut x);
        bwd = bwd.min(t.elapsed().as_secs_f64());
        let t = Instant::now();
        one.install(|| solver.backward(l, &mut y));
        bwd1 = bwd1.min(t.elapsed().as_secs_f64());
        if let (Some(sym), Some(mem)) = (chol.supernodal_symbolic(), mem.as_mut()) {
            let t = Instant::now();
            faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef::new(sym, l)
                .l_transpose_solve_with_conj(
                    faer::Conj::No,
                    faer::MatMut::from_column_major_slice_mut(&mut y, n, 1),
                    faer::Par::Seq,
                    faer::dyn_stack::MemStack::new(mem),
                );
            fb = fb.min(t.elapsed().as_secs_f64());
        }
    }
    Ok(SolveSplit {
        factor_values: chol.stats().factor_values,
        reach_rows: reach,
        full,
        forward_sparse: fwd,
        backward: bwd,
        backward_one_thread: bwd1,
        faer_backward: fb,
    })
}

/// One line for [`SolveSplit`].
pub fn format_solve_split(s: &SolveSplit) -> String {
    format!(
        "a break's solves, side by side with a full solve (factor of {:.1} M values): full solve {:.4} s; \
         sparse forward {:.4} s ({} rows reached); backward {:.4} s (one thread {:.4} s; faer's {:.4} s): {:.2} of a full solve",
        s.factor_values as f64 / 1e6,
        s.full,
        s.forward_sparse,
        s.reach_rows,
        s.backward,
        s.backward_one_thread,
        s.faer_backward,
        (s.forward_sparse + s.backward) / s.full.max(1e-12)
    )
}

/// The benchmark's table, one quantity a line.
pub fn format_fracture(t: &FractureTiming) -> String {
    let per_break = t.breaking_seconds / t.breaks.max(1) as Real;
    let refactor_total = t.refactor_seconds_per_break * t.breaks as Real;
    let split = match t.factor_space_seconds {
        Some((f, b)) => format!(
            " (of which sparse forward solves {f:.2} s, backward solves {b:.2} s: {:.4} + {:.4} s a break)",
            f / t.breaks.max(1) as Real,
            b / t.breaks.max(1) as Real
        ),
        None => String::new(),
    };
    let rest = t.breaking_seconds - t.break_solve_seconds - t.refactor_numeric_seconds;
    format!(
        "lattice {}x{}x{} cells: {} nodes, {} members, {} free DOFs\n\
         ordering + symbolic {:.3} s; one factorization {:.3} s (the run's mean {:.3} s); one solve {:.4} s\n\
         {} breaks with the factor kept (Woodbury, refactored every {} breaks: {} refactorizations): {:.2} s, {:.4} s a break = {:.1} factorizations' worth (of the mean; {:.1} of the first)\n\
         of which: solves and corrections {:.2} s{}, refactorizations {:.2} s, search and the rest {:.2} s\n\
         refactoring at every break: {:.3} s a break (measured over the first {}), so {:.1} s for {} breaks: {:.1}x slower\n\
         same members in the same order, fractions equal to 1e-9: {}\n\
         peak memory {:.0} MB",
        t.cells[0],
        t.cells[1],
        t.cells[2],
        t.nodes,
        t.members,
        t.free_dofs,
        t.symbolic_seconds,
        t.factor_seconds,
        t.mean_factor_seconds,
        t.solve_seconds,
        t.breaks,
        t.refactor_every,
        t.refactorizations,
        t.breaking_seconds,
        per_break,
        t.breaking_seconds / t.mean_factor_seconds.max(1e-12),
        t.breaking_seconds / t.factor_seconds.max(1e-12),
        t.break_solve_seconds,
        split,
        t.refactor_numeric_seconds,
        rest,
        t.refactor_seconds_per_break,
        t.compared_breaks,
        refactor_total,
        t.breaks,
        refactor_total / t.breaking_seconds.max(1e-12),
        if t.same_sequence { "yes" } else { "NO" },
        t.peak_memory as f64 / 1048576.0
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a lattice large enough for breaks in the factor's space (over 20,000 free DOFs), 30
    /// breaks with the factor kept (the Woodbury update growing to rank 30) break the same
    /// members at the same load fractions, to 1e-9, as refactoring at every break.
    #[test]
    fn breaks_in_the_factor_space_match_refactoring_at_every_break() {
        let t = measure_fracture([16, 16, 25], 30, 30).unwrap();
        assert!(t.free_dofs >= 20_000, "{} free DOFs", t.free_dofs);
        assert!(t.factor_space_seconds.is_some());
        assert_eq!((t.breaks, t.compared_breaks), (30, 30));
        assert!(t.same_sequence);
    }
}
