//! The direct solver's phases on a lattice, without CHOLMOD (for profiling):
//! `cargo run --release --example direct_phases [NX NY NZ] [REPS]` (default 40 40 40, 3).
//! Prints each repetition's wall time per phase (analysis, factorization, solve), the CPU time
//! of all threads over the three, the residual and a checksum of the solution's bits (to
//! check that repeated runs are bitwise the same).

use linkage::bench::cholmod::{cpu_seconds, lattice_system, load_average, relative_residual};
use linkage::linalg::cholesky::{CholeskyOptions, SparseCholesky};
use std::time::Instant;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("numbers: NX NY NZ [REPS]"))
        .collect();
    let cells = match args.len() {
        0 | 1 => [40, 40, 40],
        _ => [args[0], args[1], args[2]],
    };
    let reps = match args.len() {
        1 => args[0],
        4 => args[3],
        _ => 3,
    };
    let (s, members) = lattice_system(cells).expect("a valid lattice");
    println!(
        "{}x{}x{} cells: {} members, {} DOFs, nnz(A) {}",
        cells[0],
        cells[1],
        cells[2],
        members,
        s.n,
        s.row_idx.len()
    );
    let options = CholeskyOptions {
        threads: rayon::current_num_threads(),
        ..Default::default()
    };
    for rep in 1..=reps {
        let (c0, t0) = (cpu_seconds(), Instant::now());
        let mut c =
            SparseCholesky::analyze_with(s.n, &s.col_ptr, &s.row_idx, s.groups.as_deref(), options)
                .expect("analysis");
        let (c1, t1) = (cpu_seconds(), Instant::now());
        c.factorize(&s.values).expect("factorization");
        let (c2, t2) = (cpu_seconds(), Instant::now());
        let mut x = s.rhs.clone();
        c.solve_in_place(&mut x);
        let (c3, t3) = (cpu_seconds(), Instant::now());
        let bits = x.iter().fold(0u64, |h, v| h.rotate_left(7) ^ v.to_bits());
        println!(
            "rep {rep}: analyze {:.3} s (cpu {:.3}), factor {:.3} s (cpu {:.3}), solve {:.3} s (cpu {:.3}), total {:.3} s (cpu {:.3}), residual {:.2e}, bits {bits:016x}, load {:.2}",
            (t1 - t0).as_secs_f64(),
            c1 - c0,
            (t2 - t1).as_secs_f64(),
            c2 - c1,
            (t3 - t2).as_secs_f64(),
            c3 - c2,
            (t3 - t0).as_secs_f64(),
            c3 - c0,
            relative_residual(&s, &x),
            load_average().unwrap_or(f64::NAN),
        );
        drop(c);
    }
}
