"""Peers for TransCut's solves (issue #44): scipy's Jacobi-preconditioned CG
and pyamg's smoothed aggregation on the systems the `transcut` example
exports (`--export-mtx DIR`), to the same error, one thread.

    python peers.py DIR [--repeats 5] [--target 0.01] [--max-iterations 10000]
                        [--markdown] [--trilux DIR/trilux.jsonl] [--out FILE]

Every `NAME.A.mtx` in DIR (Matrix Market coordinate, 1-based) with its
`NAME.b.mtx` (right-hand side) and `NAME.x.mtx` (reference solution, to a
residual of 1e-10) is one system; other files (e.g. `NAME.B.mtx`) are
ignored. Per system, from x0 = 0:

- scipy: `scipy.sparse.linalg.cg` preconditioned by Jacobi (a LinearOperator
  applying 1/diag(A), measured faster than a diagonal sparse matrix). A first
  run finds, with a callback, the first iteration at which
  ||x - x*|| / ||x*|| <= target (1 %); the timed runs then do exactly that
  many iterations (rtol = atol = 0, maxiter = count). The timed region
  includes building the preconditioner (diagonal extraction and 1/diag), as
  trilux's Jacobi-PCG builds its preconditioner inside its solve; converting
  A to CSR float64 and reading the files are not timed.
- pyamg: `smoothed_aggregation_solver(A)` (defaults) + `ml.solve(...,
  accel='cg')`, the iteration count found the same way (callback on x), then
  setup and solve timed with tol = 0 and maxiter = count.

Times are medians of R runs (default 5) in ms; `pyamg_ms` is the median of
setup + solve per run. Output: one JSON line per system on stdout (on stderr
with --markdown), keys `system`, `n`, `nnz`, `scipy_iterations`, `scipy_ms`,
`pyamg_iterations`, `pyamg_setup_ms`, `pyamg_solve_ms`, `pyamg_ms` (an
iteration count and its times are null when the target was not reached within
--max-iterations). With --markdown, a table on stdout, with trilux's rows from
--trilux (default DIR/trilux.jsonl, the example's --json lines, matched on
their `system` key, else `mesh`) beside the peers when present.
"""

import os

# One thread for every BLAS/OpenMP pool, before numpy is imported.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import gc  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pyamg  # noqa: E402
import scipy  # noqa: E402
import scipy.io  # noqa: E402
import scipy.sparse as sp  # noqa: E402
import scipy.sparse.linalg as sla  # noqa: E402


class _Reached(Exception):
    """Raised by a callback to stop a solver once the target error is met."""


def read_matrix(path):
    """A as CSR float64 with sorted, summed indices. scipy >= 1.12's mmread
    (fast_matrix_market) reads 1.6M entries in ~80 ms here, against ~900 ms
    for np.loadtxt, ~1.1 s for np.fromstring/np.fromfile and ~1.4 s for
    bytes.split (measured on a 64k-row, 1.6M-entry file)."""
    a = sp.csr_matrix(scipy.io.mmread(path), dtype=np.float64)
    a.sum_duplicates()
    a.sort_indices()
    return a


def read_vector(path):
    return np.ascontiguousarray(np.ravel(scipy.io.mmread(path)), dtype=np.float64)


def systems(folder):
    """The NAMEs in `folder` with all of NAME.A.mtx, NAME.b.mtx and NAME.x.mtx."""
    names = []
    for name in sorted(a.name[: -len(".A.mtx")] for a in folder.glob("*.A.mtx")):
        missing = [s for s in (".b.mtx", ".x.mtx") if not (folder / (name + s)).is_file()]
        if missing:
            print(f"peers: {name}: no {', '.join(name + s for s in missing)}; skipped", file=sys.stderr)
        else:
            names.append(name)
    return names


def median(v):
    return float(np.median(v)) if v else None


def timed(fn):
    gc.collect()
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


def count_iterations(label, run, x_ref, target, cap):
    """Runs `run(callback, maxiter)` and returns the first iteration at which
    ||x - x*|| / ||x*|| <= target, or None if not within `cap`."""
    norm_ref = np.linalg.norm(x_ref)
    it = 0

    def callback(x):
        nonlocal it
        it += 1
        if np.linalg.norm(x - x_ref) <= target * norm_ref:
            raise _Reached

    try:
        run(callback, cap)
    except _Reached:
        return it
    print(f"peers: {label}: error {target:g} not reached in {cap} iterations", file=sys.stderr)
    return None


def relative_error(x, x_ref):
    return float(np.linalg.norm(x - x_ref) / np.linalg.norm(x_ref))


def scipy_solve(a, b, maxiter, callback=None):
    # Timed: the Jacobi preconditioner (diagonal and 1/diag) is built here,
    # inside the solve, as trilux's Jacobi-PCG does.
    dinv = 1.0 / a.diagonal()
    m = sla.LinearOperator(a.shape, matvec=lambda r: dinv * r, dtype=np.float64)
    x, _ = sla.cg(a, b, x0=None, rtol=0.0, atol=0.0, maxiter=maxiter, M=m, callback=callback)
    return x


def pyamg_solve(ml, b, maxiter, callback=None):
    return ml.solve(b, x0=None, tol=0.0, maxiter=maxiter, accel="cg", callback=callback)


def bench(folder, name, args):
    a = read_matrix(folder / f"{name}.A.mtx")
    b = read_vector(folder / f"{name}.b.mtx")
    x_ref = read_vector(folder / f"{name}.x.mtx")
    n = a.shape[0]
    if a.shape != (n, n) or b.shape != (n,) or x_ref.shape != (n,):
        raise ValueError(f"shapes differ: A {a.shape}, b {b.shape}, x {x_ref.shape}")
    asym = sla.norm(a - a.T) / sla.norm(a)
    if asym > 1e-10:
        print(f"peers: {name}: ||A - A^T||_F / ||A||_F = {asym:.1e}; CG assumes A symmetric", file=sys.stderr)
    row = {"system": name, "n": n, "nnz": int(a.nnz)}

    # scipy: Jacobi-PCG.
    k = count_iterations(f"{name}: scipy", lambda cb, cap: scipy_solve(a, b, cap, cb), x_ref, args.target, args.max_iterations)
    times = []
    if k is not None:
        for _ in range(args.repeats):
            t, x = timed(lambda: scipy_solve(a, b, k))
            times.append(t * 1e3)
        err = relative_error(x, x_ref)
        if err > args.target * (1 + 1e-9):
            print(f"peers: {name}: scipy's timed run ended at error {err:.3g}", file=sys.stderr)
    row["scipy_iterations"] = k
    row["scipy_ms"] = median(times)

    # pyamg: smoothed aggregation (defaults) as the preconditioner of CG.
    ml = pyamg.smoothed_aggregation_solver(a)
    k = count_iterations(f"{name}: pyamg", lambda cb, cap: pyamg_solve(ml, b, cap, cb), x_ref, args.target, args.max_iterations)
    del ml
    setup, solve, total = [], [], []
    if k is not None:
        for _ in range(args.repeats):
            ts, ml = timed(lambda: pyamg.smoothed_aggregation_solver(a))
            tv, x = timed(lambda: pyamg_solve(ml, b, k))
            del ml
            setup.append(ts * 1e3)
            solve.append(tv * 1e3)
            total.append((ts + tv) * 1e3)
        err = relative_error(x, x_ref)
        if err > args.target * (1 + 1e-9):
            print(f"peers: {name}: pyamg's timed run ended at error {err:.3g}", file=sys.stderr)
    row["pyamg_iterations"] = k
    row["pyamg_setup_ms"] = median(setup)
    row["pyamg_solve_ms"] = median(solve)
    row["pyamg_ms"] = median(total)
    return {key: (round(v, 3) if isinstance(v, float) else v) for key, v in row.items()}


def trilux_rows(path):
    """The example's --json rows by system name (`system`, else `mesh`)."""
    rows = {}
    if path is None or not path.is_file():
        return rows
    for line in path.read_text().splitlines():
        line = line.strip()
        if not line.startswith("{"):
            continue
        try:
            r = json.loads(line)
        except json.JSONDecodeError:
            continue
        key = r.get("system", r.get("mesh"))
        if key is not None:
            rows[key] = r
    return rows


def fmt(v, digits=1):
    if v is None:
        return "—"
    if isinstance(v, int):
        return f"{v:,}"
    return f"{v:,.{digits}f}"


def markdown(results, trilux, machine, target):
    with_trilux = any(r["system"] in trilux for r in results)
    head = [
        "system", "n", "nnz", "scipy CG+Jacobi iterations", "scipy ms",
        "pyamg SA iterations", "pyamg setup ms", "pyamg solve ms", "pyamg ms",
    ]
    if with_trilux:
        head += ["trilux solver", "trilux ms (hierarchy + T_s, per channel)", "vs scipy", "vs pyamg"]
    align = ["---" if h in ("system", "trilux solver") else "---:" for h in head]
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join(align) + "|"]
    dagger = False
    for r in results:
        cells = [
            r["system"], fmt(r["n"]), fmt(r["nnz"]), fmt(r["scipy_iterations"]), fmt(r["scipy_ms"]),
            fmt(r["pyamg_iterations"]), fmt(r["pyamg_setup_ms"]), fmt(r["pyamg_solve_ms"]), fmt(r["pyamg_ms"]),
        ]
        if with_trilux:
            t = trilux.get(r["system"])
            ms, mark = None, ""
            if t is not None and t.get("ts_ms") is not None:
                if t.get("hierarchy_ms") is not None:
                    ms = t["hierarchy_ms"] + t["ts_ms"]
                elif t.get("tb_ms") is not None:
                    ms, mark, dagger = t["tb_ms"] + t["ts_ms"], " †", True
            speedup = lambda peer: (  # noqa: E731
                f"{peer / ms:.2f}×" if ms and peer is not None else "—"
            )
            cells += [
                (t or {}).get("solver", "—"), fmt(ms) + mark, speedup(r["scipy_ms"]), speedup(r["pyamg_ms"]),
            ]
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")
    lines.append(
        f"Peers from x0 = 0 to ||x − x*||/||x*|| ≤ {100 * target:g} % against the exported reference, one thread, "
        f"median of {machine['repeats']} runs; scipy's time includes building the Jacobi preconditioner "
        f"(1/diag), pyamg ms = setup + solve. {machine['text']}"
    )
    if with_trilux:
        lines.append("'vs' = peer time / trilux time (> 1: trilux faster).")
    if dagger:
        lines.append("† no `hierarchy_ms` in trilux's row: T_b (mesh neighbourhoods + hierarchy) + T_s, which overstates the solve.")
    return "\n".join(lines)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("folder", type=Path, help="the folder of NAME.A.mtx / NAME.b.mtx / NAME.x.mtx")
    p.add_argument("--repeats", type=int, default=5, help="timed runs per solver (median); default 5")
    p.add_argument("--target", type=float, default=0.01, help="relative error against NAME.x.mtx; default 0.01")
    p.add_argument("--max-iterations", type=int, default=10000, help="give up beyond this; default 10000")
    p.add_argument("--markdown", action="store_true", help="print a Markdown table (JSON lines go to stderr)")
    p.add_argument("--trilux", type=Path, help="the example's --json lines; default FOLDER/trilux.jsonl")
    p.add_argument("--out", type=Path, help="also write the JSON lines to this file")
    args = p.parse_args()
    if args.repeats < 1 or args.max_iterations < 1:
        p.error("--repeats and --max-iterations must be at least 1")

    load = os.getloadavg()[0]
    machine = {
        "repeats": args.repeats,
        "text": f"nproc {os.cpu_count()}, load average (1 min) {load:.2f} at start; "
        f"numpy {np.__version__}, scipy {scipy.__version__}, pyamg {pyamg.__version__}.",
    }
    print(f"peers: {machine['text']}", file=sys.stderr, flush=True)

    names = systems(args.folder)
    if not names:
        print(f"peers: no NAME.A.mtx with NAME.b.mtx and NAME.x.mtx in {args.folder}", file=sys.stderr)
        return 1
    json_out = sys.stderr if args.markdown else sys.stdout
    out_file = args.out.open("w") if args.out else None
    results = []
    for name in names:
        try:
            row = bench(args.folder, name, args)
        except Exception as e:  # one bad system does not end the run
            print(f"peers: {name}: {type(e).__name__}: {e}", file=sys.stderr)
            continue
        results.append(row)
        line = json.dumps(row)
        print(line, file=json_out, flush=True)
        if out_file:
            print(line, file=out_file, flush=True)
    if out_file:
        out_file.close()
    if args.markdown:
        machine["text"] += f" Load average (1 min) at the end {os.getloadavg()[0]:.2f}."
        trilux = trilux_rows(args.trilux if args.trilux else args.folder / "trilux.jsonl")
        print(markdown(results, trilux, machine, args.target))
    return 0 if results else 1


if __name__ == "__main__":
    sys.exit(main())
