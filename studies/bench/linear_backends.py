"""Cost of the linear-solver backends on P1 elasticity step matrices.

For the unit square (2D) and cube (3D) clamped on x = 0 (E = 1000,
ν = 0.3) at a few sizes, and each backend of
:mod:`adhesive_contact.linear_solvers`, it measures: the set-up
(factorisation or AMG hierarchy), one solve with one right-hand side
(median of 3), one solve with a block of 16, the largest relative residual
of the block, and the peak resident memory of the process that did it. It
prints a table and writes ``linear_backends.csv`` and
``linear_backends.json`` beside this script.

    python studies/bench/linear_backends.py [--threads 1] [--quick --out DIR]

Each (size, backend) runs in its own process, which loads the matrix from
a file: its peak RSS (Linux's VmHWM) minus its RSS after loading and after
a warm-up solve on a small block is the memory of the solver (set-up and solves of
one and of 16 right-hand sides, whose arrays add 16 n doubles). MKL runs on ``--threads`` threads (1 by
default: the machine is shared, and the time loop keeps BLAS on one thread
anyway); PARDISO is also measured on 2 threads. A backend is skipped at a
size where its estimated factors (``factor_bytes``) pass 2 GB: SuperLU in
3D, whose minimum degree ordering fills about n^(5/3).
"""

import argparse
import csv
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

HERE = Path(__file__).resolve().parent
SIZES = {2: (70, 224, 360), 3: (14, 23, 30)}   # cells per side: ~1e4, 1e5, 2.6e5 / 1e4, 4e4, 9e4 dofs
BACKENDS = ("pardiso", "superlu", "amg")
SKIP_BYTES = 2e9
E, NU = 1000.0, 0.3
LAM, MU = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))


def build(dim, cells, path):
    """Assemble the clamped stiffness and save (A, points, free) to path."""
    from skfem import MeshTet, MeshTri

    from adhesive_contact.fem.assembly import Assembly, stiffness_basis
    from adhesive_contact.fem.meshes import side_tests

    axes = [np.linspace(0.0, 1.0, cells + 1)] * dim
    mesh = (MeshTri if dim == 2 else MeshTet).init_tensor(*axes).with_boundaries(
        side_tests([1.0] * dim))
    assembly = Assembly(mesh)
    clamped = stiffness_basis(mesh).get_dofs("left").flatten()
    free = np.setdiff1d(np.arange(assembly.ndofs), clamped)
    A = assembly.stiffness(LAM, MU)[free][:, free].tocsr()
    np.savez(path, data=A.data, indices=A.indices, indptr=A.indptr, shape=A.shape,
             points=mesh.p, free=free)
    return A.shape[0], A.nnz


def status_mb(key):
    """VmRSS (now) or VmHWM (peak) of this process in MB, from /proc (Linux)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1]) / 1024
    raise KeyError(key)


def reset_peak():
    """Restart VmHWM from VmRSS (Linux ≥ 4.0). getrusage's ru_maxrss can't be
    used: it is kept across execve, so a child starts with its parent's."""
    Path("/proc/self/clear_refs").write_text("5")


def measure(path, backend, threads):
    """Run in a child process: one backend on the saved matrix."""
    import pyamg  # noqa: F401  (loaded before the baseline: libraries are not the solver's memory)
    from threadpoolctl import threadpool_limits

    from adhesive_contact.linear_solvers import make_linear_solver, pardiso

    pardiso.available()   # finds and loads MKL once, outside the set-up time
    f = np.load(path)
    A = sp.csr_matrix((f["data"], f["indices"], f["indptr"]), shape=tuple(f["shape"]))
    points, free = f["points"], f["free"]
    rng = np.random.default_rng(0)
    b, B = rng.standard_normal(A.shape[0]), rng.standard_normal((A.shape[0], 16))
    with threadpool_limits(threads, user_api="blas"):
        # warm-up on a leading block (SPD too): code loaded on first use is not the solver's
        m = min(300, A.shape[0])
        make_linear_solver(A[:m, :m], backend, dim=points.shape[0], points=points,
                           dofs=free[:m]).solve(b[:m])
        base = status_mb("VmRSS")
        reset_peak()
        solver = make_linear_solver(A, backend, dim=points.shape[0], points=points, dofs=free)
        one = []
        for _ in range(3):
            t0 = time.perf_counter()
            solver.solve(b)
            one.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        X = solver.solve(B)
        block = time.perf_counter() - t0
    residual = np.linalg.norm(B - A @ X, axis=0) / np.linalg.norm(B, axis=0)
    peak = status_mb("VmHWM")
    return {"setup_s": solver.setup_seconds, "solve1_s": float(np.median(one)),
            "solve16_s": block, "max_rel_residual": float(residual.max()),
            "peak_rss_mb": peak, "solver_rss_mb": peak - base, "info": solver.info}


def run_child(path, backend, threads, timeout=600):
    out = subprocess.run([sys.executable, __file__, "--child", str(path), backend, str(threads)],
                         capture_output=True, text=True, timeout=timeout, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def write_atomic(path, text):
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def versions():
    from importlib.metadata import PackageNotFoundError, version

    found = {}
    for name in ("numpy", "scipy", "pyamg", "pypardiso", "mkl", "scikit-fem"):
        try:
            found[name] = version(name)
        except PackageNotFoundError:
            found[name] = None
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--quick", action="store_true", help="one small size per dimension")
    parser.add_argument("--out", default=str(HERE), help="folder for the CSV and JSON")
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        path, backend, threads = args.child
        print(json.dumps(measure(path, backend, int(threads))))
        return

    from adhesive_contact.linear_solvers import choose, factor_bytes, pardiso

    sizes = {2: (20,), 3: (6,)} if args.quick else SIZES
    backends = [b for b in BACKENDS if b != "pardiso" or pardiso.available()]
    runs = [(b, args.threads) for b in backends]
    if "pardiso" in backends and args.threads != 2:
        runs.insert(1, ("pardiso", 2))
    rows = []
    t_start = time.perf_counter()
    print(f"{'dim':>3} {'dofs':>7} {'backend':>8} {'thr':>3} {'setup s':>8} {'solve s':>8} "
          f"{'16 rhs s':>8} {'resid':>8} {'RSS MB':>7} {'solver MB':>9}  notes", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        for dim, cells_list in sizes.items():
            for cells in cells_list:
                path = Path(tmp) / f"A{dim}_{cells}.npz"
                n, nnz = build(dim, cells, path)
                auto, reason = choose(n, nnz, dim)
                for backend, threads in runs:
                    row = {"dim": dim, "cells": cells, "dofs": n, "nnz": nnz,
                           "backend": backend, "threads": threads, "auto": auto}
                    estimate = factor_bytes(n, nnz, dim, backend) if backend != "amg" else None
                    row["estimated_factor_mb"] = None if estimate is None else estimate / 1e6
                    if estimate is not None and estimate > SKIP_BYTES:
                        row["status"] = (f"skipped: estimated factors {estimate / 1e9:.1f} GB "
                                         f"(> {SKIP_BYTES / 1e9:.0f} GB), and minutes to factorise")
                        print(f"{dim:>3} {n:>7} {backend:>8} {threads:>3}  {row['status']}",
                              flush=True)
                        rows.append(row)
                        continue
                    row.update(run_child(path, backend, threads), status="ok")
                    info = row["info"]
                    note = (f"factor nnz {info['factor_nnz']:.3g}" if "factor_nnz" in info else
                            f"{info['levels']} levels, op. complexity "
                            f"{info['operator_complexity']:.2f}, {info['iterations']} CG it")
                    print(f"{dim:>3} {n:>7} {backend:>8} {threads:>3} {row['setup_s']:>8.3f} "
                          f"{row['solve1_s']:>8.4f} {row['solve16_s']:>8.3f} "
                          f"{row['max_rel_residual']:>8.1e} {row['peak_rss_mb']:>7.0f} "
                          f"{row['solver_rss_mb']:>9.0f}  {note}", flush=True)
                    rows.append(row)
                print(f"    auto: {reason}", flush=True)

    meta = {"machine": platform.machine(), "cpus": os.cpu_count(), "threads": args.threads,
            "python": platform.python_version(), "versions": versions(),
            "total_seconds": time.perf_counter() - t_start}
    out = Path(args.out)
    write_atomic(out / "linear_backends.json", json.dumps({"meta": meta, "rows": rows}, indent=1))
    fields = ["dim", "cells", "dofs", "nnz", "backend", "threads", "status", "setup_s",
              "solve1_s", "solve16_s", "max_rel_residual", "peak_rss_mb", "solver_rss_mb",
              "estimated_factor_mb", "factor_nnz", "auto"]
    with open(out / "linear_backends.csv.tmp", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({**row, "factor_nnz": row.get("info", {}).get("factor_nnz")})
    os.replace(out / "linear_backends.csv.tmp", out / "linear_backends.csv")
    print(f"total {meta['total_seconds']:.0f} s", flush=True)


if __name__ == "__main__":
    main()
