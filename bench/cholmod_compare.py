"""Time CHOLMOD (scikit-sparse) on a matrix written by `linkage bench --cholmod`.

Usage: python cholmod_compare.py SYSTEM.npz [fill]

SYSTEM.npz holds the lower triangle of a symmetric positive definite matrix in CSC form
(`n`, `col_ptr`, `row_idx`, `values`) and a right-hand side `rhs`. The script orders it with
METIS, factors it (supernodal LL^T) and solves once, timing the three phases (wall and CPU
time of this process, all threads), checks the relative residual ||b - A x|| / ||b|| and prints
one JSON line; with `fill` also the entries of L (an untimed conversion of the factor). Needs numpy, scipy and scikit-sparse 0.4.16 over SuiteSparse with an optimised
BLAS (see docs/PERFORMANCE.md, "Against CHOLMOD").
"""

import json
import sys
import time

try:
    import numpy as np
    import scipy.sparse as sp
    from sksparse.cholmod import analyze
except ImportError as e:  # the message the Rust side shows
    sys.stderr.write(
        f"cholmod_compare.py needs numpy, scipy and scikit-sparse ({e}); "
        "install them as docs/PERFORMANCE.md says and pass that Python with --python\n"
    )
    sys.exit(3)


def main():
    if len(sys.argv) not in (2, 3):
        sys.stderr.write("usage: cholmod_compare.py SYSTEM.npz [fill]\n")
        sys.exit(2)
    with np.load(sys.argv[1]) as d:
        n = int(d["n"])
        lower = sp.csc_matrix((d["values"], d["row_idx"], d["col_ptr"]), shape=(n, n))
        b = np.array(d["rhs"], dtype=np.float64)
    # CHOLMOD is given the whole symmetric matrix (scikit-sparse's convention); building it
    # is not timed.
    a = (lower + lower.T - sp.diags(lower.diagonal())).tocsc()
    a.sort_indices()

    wall, cpu = time.perf_counter, time.process_time
    w0, c0 = wall(), cpu()
    factor = analyze(a, mode="supernodal", ordering_method="metis")
    w1, c1 = wall(), cpu()
    factor.cholesky_inplace(a)
    w2, c2 = wall(), cpu()
    x = factor(b)
    w3, c3 = wall(), cpu()

    residual = float(np.linalg.norm(b - a @ x) / np.linalg.norm(b))
    nnz_l = int(factor.L().nnz) if sys.argv[2:] == ["fill"] else None
    print(
        json.dumps(
            {
                "analyze": w1 - w0,
                "factor": w2 - w1,
                "solve": w3 - w2,
                "cpu": c3 - c0,
                "residual": residual,
                "nnz_l": nnz_l,
            }
        )
    )


if __name__ == "__main__":
    main()
