"""Command line: ``python -m particle_entropy simulate ...`` runs one simulation to Parquet."""

from __future__ import annotations

import argparse
import math
import os
import signal
import sys

from .core.case import NONE, from_text
from .core.registry import ALL_KERNELS, DEFAULT_KERNEL, KERNELS, METHODS, SCHEME_DOCS
from .core.runconfig import RunConfig, SettingError
from .core.settings import BY_NAME, PAPER, Setting

# The run settings the simulate command takes, as options named and described by settings.py.
# dt0 and dt_growth have method-dependent defaults (None here, filled by RunConfig).
CLI_SETTINGS = (
    "eta",
    "truncation",
    "dt_growth",
    "scheme",
    "D",
    "t_final",
    "dt0",
    "omega",
    "fd_length",
    "fixed_kernel_time",
    "transfer_method",
    "transfer_tolerance",
    "loop_arithmetic",
    "time_grid",
)
CHOICE_DOCS = {"scheme": SCHEME_DOCS}  # what each choice means, in the option's help
METHOD_DEFAULTS = {
    "dt0": f"{PAPER['dt0']:g}; fixed step {PAPER['fixed_dt']:g} when dt-growth is 1; fd: {PAPER['fd_dt']:g}",
    "dt_growth": f"{PAPER['dt_growth']:g}; fd: 1",
}


def _number_or_none(text: str):
    """An option value: a number, or the word none (a truncation's whole Gaussian)."""
    if from_text(text) is None:
        return None
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'none' or a number, got {text!r}") from None


def _add_setting(parser: argparse.ArgumentParser, setting: Setting) -> None:
    """The option of one setting: its type, choices, default and help from its definition."""
    default = None if setting.name in METHOD_DEFAULTS else setting.default
    shown = METHOD_DEFAULTS.get(
        setting.name, NONE if default is None else f"{default:g}" if isinstance(default, float) else default
    )
    unit = "" if setting.unit == "-" else f" [{setting.unit}]"
    kwargs = {"default": default, "help": f"{setting.doc}{unit}; {setting.allowed()} (default: {shown})"}
    if setting.choices is not None:
        words = CHOICE_DOCS.get(setting.name, {})
        kwargs["choices"] = setting.choices
        kwargs["help"] = f"{setting.doc} (default: {shown})" + "".join(f"; {k}: {v}" for k, v in words.items())
    elif setting.none:
        kwargs.update(type=_number_or_none, metavar="{none,<number>}")
    else:
        kwargs["type"] = float
    parser.add_argument(setting.option, **kwargs)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m particle_entropy", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser(
        "simulate",
        help="run one simulation and write its per-step table",
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
    s.add_argument("--seed", type=int, default=0, help="random seed (>= 0)")
    for name in CLI_SETTINGS:
        _add_setting(s, BY_NAME[name])
    s.add_argument("--out", required=True, help="output Parquet path (per-step table)")
    s.add_argument("--state-out", default=None, help="optional Parquet path for the final state (x, mass, c)")
    s.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    c = sub.add_parser(
        "check-config",
        help="check workflow config files as a dry run would, with YAML line numbers",
        description="Check one or more workflow config files, merged in order as Snakemake merges "
        "config.yaml and --configfile: YAML syntax (line and column), the schema and every rule "
        "between fields. Exit 0 when the workflow would accept them, 2 otherwise. An adaptive "
        "search or a scene is judged, as by the run, only for its own targets: one that they would "
        "refuse is named on a line of its own, not judged against the rest. Only regular files of "
        "at most 1 MB are read.",
    )
    c.add_argument("files", nargs="+", help="YAML config files, later ones overriding earlier ones")
    return p


def check_config_files(files: list[str]) -> int:
    """The check-config command: merge the files, check them as the run would, print one line (and
    one line for each search or scene that only its own targets would refuse)."""
    from snakemake.utils import update_config

    from .pipeline.configcheck import ConfigFileError, check_config, load_yaml
    from .pipeline.memory import available_bytes

    config: dict = {}
    not_judged: list[str] = []
    try:
        for f in files:
            update_config(config, dict(load_yaml(f)))
        check_config(config, available=available_bytes(), not_judged=not_judged)  # the dry run's checks
    except (ConfigFileError, SettingError, OSError) as e:
        print(f"check-config: {e}", file=sys.stderr)
        return 2
    print(f"check-config: {' + '.join(files)}: accepted")
    for line in not_judged:
        print(f"check-config: {line}")
    return 0


def config_from_args(a: argparse.Namespace) -> RunConfig:
    settings = {name: getattr(a, name) for name in CLI_SETTINGS}
    return RunConfig.of(method=a.method, kernel=a.kernel, n=a.n, seed=a.seed, **settings).resolved()


def _same_file(a: str, b: str) -> bool:
    """Whether two paths name one file: the same path once links are resolved (a symlinked
    folder, a file not yet made), or an existing file reached twice (a hard link)."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist yet: different files
        return False


class Stopped(Exception):
    """SIGTERM, raised where the run is (as SIGINT raises KeyboardInterrupt), so that it ends as SIGINT does."""


def _stop(signum, frame):
    raise Stopped(signum)


def main(argv=None) -> int:
    parser = build_parser()
    a = parser.parse_args(argv)
    if a.command == "check-config":
        return check_config_files(a.files)
    before = _identity(a.out)
    previous = signal.signal(signal.SIGTERM, _stop)
    try:
        return simulate(parser, a)
    except (KeyboardInterrupt, Stopped) as e:
        # one line, no traceback; exit 128 + the signal's number, as a shell reports a process it ended
        signum = e.args[0] if isinstance(e, Stopped) else signal.SIGINT
        outputs = " and ".join(flag for flag, target in (("--out", a.out), ("--state-out", a.state_out)) if target)
        written = _identity(a.out) != before  # a new table is a new file (io: renamed into place)
        what = f"{outputs} written" if written else f"nothing written ({outputs} as they were)"
        print(f"simulate: stopped by {signal.Signals(signum).name}; {what}", file=sys.stderr)
        return 128 + signum
    finally:
        signal.signal(signal.SIGTERM, previous)


def _identity(path: str) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_ino, st.st_mtime_ns


def simulate(parser: argparse.ArgumentParser, a: argparse.Namespace) -> int:
    """The simulate command, after its arguments are parsed."""
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
    from .core.timegrid import step_count
    from .pipeline.memory import available_bytes, estimate_bytes

    need, have = estimate_bytes(cfg), available_bytes()
    if have is not None and need > have:
        steps = step_count(cfg.t_final, cfg.dt0, cfg.dt_growth)
        parser.error(
            f"--n {cfg.n} and {steps:,} time steps need about {need / 1e9:.2f} GB (the {cfg.method} arrays and "
            f"one table row per step), more than the {have / 1e9:.2f} GB available on this machine: "
            "lower --n or take fewer, longer steps (--dt0, --dt-growth)"
        )
    from .core.heap import keep_freed_pages
    from .core.io import write_parquet, write_run
    from .models.simulate import run

    keep_freed_pages()  # steps reuse the pages of the last step's arrays
    progress = None if a.quiet else (lambda msg: print(msg, file=sys.stderr, flush=True))
    table, state = run(cfg, progress=progress, want_state=a.state_out is not None)
    if state is None:
        write_parquet(table, a.out)
    else:  # one run's pair: named by a run id in each, so tables of two runs are never taken for one
        write_run({a.out: table, a.state_out: state})
    last = table.iloc[-1]
    if progress:
        progress(
            f"done: {len(table) - 1} steps, t={last['time']:.6g}, H_C={last['H_C']:.6g}, "
            f"mass error={abs(last['mass_total'] - 1):.3g}, wall={table['wall_s'].sum():.2f}s"
        )
    from .analysis.aggregate import unscored

    why = unscored(last["SSE"], last["dV"]).item()
    if why:  # a valid run that COMIC cannot score: said, even with --quiet (the tables hold COMIC NaN)
        print(f"warning: COMIC at t={last['time']:.6g} does not score this run: {why}", file=sys.stderr)
    return 0 if math.isfinite(last["mass_total"]) else 1
