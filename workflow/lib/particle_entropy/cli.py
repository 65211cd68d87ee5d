"""Command line: ``python -m particle_entropy simulate ...`` runs one simulation to Parquet."""

from __future__ import annotations

import argparse
import math
import os
import sys

from .core.registry import (
    ALL_KERNELS,
    DEFAULT_KERNEL,
    KERNELS,
    METHODS,
    PAPER,
    SCHEME_DOCS,
    SCHEMES,
    TIME_GRIDS,
    TRANSFER_METHODS,
)
from .core.runconfig import RunConfig, SettingError


def _truncation(text: str):
    if text.lower() == "none":
        return None
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'none' or a number of kernel widths > 0, got {text!r}") from None


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m particle_entropy", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser(
        "simulate",
        help="run one simulation and write its per-step table",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
        description="Run one PT, MTPT or FD simulation of 1-D diffusion from a delta at x = 0 "
        "and write one row per time step (entropies, dilution index, SSE, COMIC, mass, cost) as Parquet.",
    )
    by_method = "; ".join(f"{m}: {'|'.join(KERNELS[m])}" for m in METHODS)
    s.add_argument(
        "--method",
        choices=METHODS,
        default="mtpt",
        help="pt: random walks; mtpt: mass transfer; fd: finite differences",
    )
    s.add_argument(
        "--kernel",
        choices=ALL_KERNELS,
        default=None,
        help=f"{by_method}. Default: {', '.join(DEFAULT_KERNEL[m] for m in METHODS)}",
    )
    s.add_argument("--n", type=int, default=300, help="particles (pt, mtpt) or FD intervals, dx = L / N [-]")
    s.add_argument(
        "--eta", type=float, default=PAPER["eta"], help="mtpt: fraction of D done by mass transfer, in [0, 1] [-]"
    )
    s.add_argument("--D", type=float, default=PAPER["D"], help="diffusion coefficient [L^2/T]")
    s.add_argument("--t-final", type=float, default=PAPER["t_final"], help="final time [T]")
    s.add_argument(
        "--dt0",
        type=float,
        default=None,
        help=f"first time step [T] (default {PAPER['dt0']:g}; fixed step {PAPER['fixed_dt']:g} when "
        f"dt-growth is 1; fd: {PAPER['fd_dt']:g})",
    )
    s.add_argument(
        "--dt-growth",
        type=float,
        default=None,
        help=f"dt_{{n+1}} = growth dt_n, 1 = fixed step [-] (default {PAPER['dt_growth']:g}; fd: 1)",
    )
    s.add_argument(
        "--truncation",
        type=_truncation,
        default=None,
        metavar="{none,<widths>}",
        help="truncate the transfer kernel at this many kernel widths; none = whole Gaussian (Eqs. 17, 21)",
    )
    s.add_argument("--seed", type=int, default=0, help="random seed (>= 0)")
    s.add_argument("--omega", type=float, default=PAPER["omega"], help="particle domain length Omega [L]")
    s.add_argument("--fd-length", type=float, default=PAPER["fd_length"], help="FD domain length [L], centred on 0")
    s.add_argument(
        "--fixed-kernel-time",
        type=float,
        default=PAPER["fixed_kernel_time"],
        help="pt fixed kernel: reconstruct with variance 2 D x this time [T]",
    )
    s.add_argument(
        "--transfer-method",
        choices=TRANSFER_METHODS,
        default=PAPER["transfer_method"],
        help="Gauss-transform algorithm for mass transfer (auto picks the faster exact one)",
    )
    s.add_argument(
        "--transfer-tolerance",
        type=float,
        default=PAPER["transfer_tolerance"],
        help="error bound of the fast Gauss transform, relative to the summed |weights| in reach "
        f"[-] (default {PAPER['transfer_tolerance']:g}: round-off, mass conserved to 1e-13)",
    )
    s.add_argument(
        "--scheme",
        choices=SCHEMES,
        default=PAPER["scheme"],
        help="mtpt: " + "; ".join(f"{k}: {v}" for k, v in SCHEME_DOCS.items()),
    )
    s.add_argument(
        "--time-grid",
        choices=TIME_GRIDS,
        default=PAPER["time_grid"],
        help="particles: exact = last step shortened to end at t-final; authors = whole steps while "
        "t < t-final, as the authors' code (175 steps to t = 1021.1 for the defaults)",
    )
    s.add_argument("--out", required=True, help="output Parquet path (per-step table)")
    s.add_argument("--state-out", default=None, help="optional Parquet path for the final state (x, mass, c)")
    s.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    c = sub.add_parser(
        "check-config",
        help="check workflow config files as a dry run would, with YAML line numbers",
        description="Check one or more workflow config files, merged in order as Snakemake merges "
        "config.yaml and --configfile: YAML syntax (line and column), the schema and every rule "
        "between fields. Exit 0 when the workflow would accept them, 2 otherwise.",
    )
    c.add_argument("files", nargs="+", help="YAML config files, later ones overriding earlier ones")
    return p


def check_config_files(files: list[str]) -> int:
    """The check-config command: merge the files, check them, print one line."""
    from snakemake.utils import update_config

    from .pipeline.configcheck import ConfigFileError, check_config, load_yaml

    config: dict = {}
    try:
        for f in files:
            update_config(config, dict(load_yaml(f)))
        check_config(config)
    except (ConfigFileError, SettingError, OSError) as e:
        print(f"check-config: {e}", file=sys.stderr)
        return 2
    print(f"check-config: {' + '.join(files)}: accepted")
    return 0


def config_from_args(a: argparse.Namespace) -> RunConfig:
    return RunConfig(
        method=a.method,
        kernel=a.kernel,
        n=a.n,
        eta=a.eta,
        D=a.D,
        t_final=a.t_final,
        dt0=a.dt0,
        dt_growth=a.dt_growth,
        truncation=a.truncation,
        seed=a.seed,
        omega=a.omega,
        fd_length=a.fd_length,
        fixed_kernel_time=a.fixed_kernel_time,
        transfer_method=a.transfer_method,
        transfer_tolerance=a.transfer_tolerance,
        scheme=a.scheme,
        time_grid=a.time_grid,
    ).resolved()


def _same_file(a: str, b: str) -> bool:
    """Whether two paths name one file: the same path once links are resolved (a symlinked
    folder, a file not yet made), or an existing file reached twice (a hard link)."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist yet: different files
        return False


def main(argv=None) -> int:
    parser = build_parser()
    a = parser.parse_args(argv)
    if a.command == "check-config":
        return check_config_files(a.files)
    try:
        cfg = config_from_args(a)
    except SettingError as e:
        parser.error(f"--{e.name.replace('_', '-')}: {e}")
    from .core.io import OutputError, check_output_path

    if a.state_out is not None and _same_file(a.state_out, a.out):
        parser.error(f"--state-out: {a.state_out!r} is also --out; the final state would replace the per-step table")
    for flag, target in (("--out", a.out), ("--state-out", a.state_out)):
        if target is not None:
            try:
                check_output_path(target)
            except OutputError as e:
                parser.error(f"{flag}: {e}")
    from .core.memory import available_bytes, estimate_bytes
    from .core.timegrid import step_count

    need, have = estimate_bytes(cfg), available_bytes()
    if have is not None and need > have:
        steps = step_count(cfg.t_final, cfg.dt0, cfg.dt_growth)
        parser.error(
            f"--n {cfg.n} and {steps:,} time steps need about {need / 1e9:.2f} GB (the {cfg.method} arrays and "
            f"one table row per step), more than the {have / 1e9:.2f} GB available on this machine: "
            "lower --n or take fewer, longer steps (--dt0, --dt-growth)"
        )
    from .core.heap import keep_freed_pages
    from .core.io import write_parquet
    from .models.simulate import run

    keep_freed_pages()  # steps reuse the pages of the last step's arrays
    progress = None if a.quiet else (lambda msg: print(msg, file=sys.stderr, flush=True))
    table, state = run(cfg, progress=progress, want_state=a.state_out is not None)
    write_parquet(table, a.out)
    if state is not None:
        write_parquet(state, a.state_out)
    last = table.iloc[-1]
    if progress:
        progress(
            f"done: {len(table) - 1} steps, t={last['time']:.6g}, H_C={last['H_C']:.6g}, "
            f"mass error={abs(last['mass_total'] - 1):.3g}, wall={table['wall_s'].sum():.2f}s"
        )
    return 0 if math.isfinite(last["mass_total"]) else 1
