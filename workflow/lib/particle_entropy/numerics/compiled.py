"""The compiled kernels a simulation calls: numba's JIT, or the same kernels compiled ahead of time.

Callers reach every numba kernel of the symmetric MTPT transfer, the kernel reconstructions, the
finite differences and the authors' sequential loop through ``kernels()``, by the names of
``EXPORTS``. By default that is numba's JIT: the kernels are compiled, or loaded from numba's
on-disk cache, on first call, and a process pays for numba itself first (import 0.15 s, target
set-up 0.3 s, which also imports scipy.linalg), more than a small job's whole run.

A simulation job instead calls ``use(folder)`` with a module that ``build(folder)`` compiled
ahead of time from the same kernels (the workflow's rule ``compile_kernels``, once per code
version), and so imports no numba at all. Its results are the same bits as the JIT's: the build
hands LLVM the target the JIT would (this CPU's name and features, numba's settings), each
kernel keeps its own flags (fastmath where it has them), and each is exported with the one
signature runs call it with. ``use`` takes the module only if it was built from this code, by
this numba, for this CPU and numba settings (``target()``); else the job runs the JIT as before.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import os
import sys
import types
from pathlib import Path

MODULE = "particle_entropy_kernels"  # the extension module's name (its init function's)
TARGET_FILE = "target.txt"  # beside the module: what it was built from and for (target())
# kernel -> (module of numerics, signature): the arrays and scalars runs pass (C-contiguous
# float64 arrays; Python floats, ints and bools), and what each kernel returns
EXPORTS = {
    "direct": ("gauss_kernels", "f8[:, ::1](f8[::1], f8[::1], f8[:, ::1], f8, f8, b1)"),
    "direct_symmetric": ("gauss_kernels", "f8[:, ::1](f8[::1], f8[:, ::1], f8, f8)"),
    "fgt": ("gauss_kernels", "f8[:, ::1](f8[::1], f8[::1], f8[:, ::1], f8, f8, i8[::1])"),
    "taylor_moments": ("gauss_kernels", "Tuple((f8[::1], f8[:, :, ::1]))(f8[::1], f8[:, ::1], f8, f8, i8)"),
    "taylor_eval": ("gauss_kernels", "f8[:, ::1](f8[::1], f8[::1], f8[:, :, ::1], f8, f8)"),
    "weights": ("transfer_kernels", "Tuple((f8[::1], f8[:, ::1]))(f8[::1], f8[::1])"),
    "offdiag": ("transfer_kernels", "Tuple((f8[::1], f8, f8))(f8[::1], f8[::1], f8[::1], f8)"),
    "update": ("transfer_kernels", "f8[::1](f8[::1], f8[::1], f8, f8[::1], f8[::1], f8[::1])"),
    "thomas_factor": ("thomas", "UniTuple(f8[::1], 2)(i8, f8)"),
    "thomas_solve": ("thomas", "f8[::1](f8[::1], f8[::1], f8, f8[::1])"),
    # the authors' loop: (x, m, label, sigma, radius, beta, seed, symnorm, clip) -> m
    "_sweep": ("sequential_kernels", "f8[::1](f8[::1], f8[::1], i8[::1], f8, f8, f8, u8, b1, b1)"),
    "_sweep_fma": ("sequential_kernels", "f8[::1](f8[::1], f8[::1], i8[::1], f8, f8, f8, u8, b1, b1)"),
}
# numba settings that change the machine code the JIT makes (numba.core.config)
CODEGEN_SETTINGS = ("NUMBA_OPT", "NUMBA_ENABLE_AVX", "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "NUMBA_LOOP_VECTORIZE")

_loaded: types.ModuleType | None = None


def kernels():
    """The kernels' namespace: the ahead-of-time module a job took (``use``), else numba's JIT."""
    return _loaded if _loaded is not None else _jit()


@functools.cache
def _jit() -> types.SimpleNamespace:
    modules = _kernel_modules()
    return types.SimpleNamespace(**{name: getattr(modules[mod], name) for name, (mod, _) in EXPORTS.items()})


def _kernel_modules() -> dict[str, types.ModuleType]:
    """The modules of EXPORTS' kernels by name (importing them imports numba)."""
    from . import gauss_kernels, sequential_kernels, thomas, transfer_kernels

    return {
        "gauss_kernels": gauss_kernels,
        "transfer_kernels": transfer_kernels,
        "thomas": thomas,
        "sequential_kernels": sequential_kernels,
    }


def code_key() -> str:
    """SHA-256 of the kernels' code: this module, the kernel modules and what they import."""
    digest = hashlib.sha256()
    kernel_files = ("gauss_kernels.py", "transfer_kernels.py", "thomas.py", "sequential_kernels.py")
    for name in ("compiled.py", *kernel_files, "fastexp.py"):
        digest.update((Path(__file__).with_name(name)).read_bytes())
    return digest.hexdigest()


def _cpu() -> str | None:
    """The first processor's vendor, model and flags (Linux's /proc/cpuinfo), which fix the CPU
    name and features LLVM finds; None where there is no such file."""
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return None
    first = text.split("\n\n")[0]
    keep = ("vendor_id", "cpu family", "model", "model name", "stepping", "flags")
    lines = [line for line in first.splitlines() if line.split(":")[0].strip() in keep]
    return hashlib.sha256("\n".join(lines).encode()).hexdigest() if lines else None


def target(numba_version: str | None = None) -> str | None:
    """What a module must have been built from and for to stand in for the JIT here: the kernels'
    code, numba's version, the CPU and numba's code-generation settings; None where the CPU is
    unknown (the JIT then always runs)."""
    cpu = _cpu()
    if cpu is None:
        return None
    if numba_version is None:
        from importlib.metadata import version

        numba_version = version("numba")
    settings = " ".join(f"{k}={os.environ[k]}" for k in CODEGEN_SETTINGS if k in os.environ)
    return f"code {code_key()}\nnumba {numba_version}\ncpu {cpu}\nsettings {settings}\n"


def kernels_folder(root: str = "results/kernels") -> str:
    """Where the workflow keeps the module built for ``target()``: a folder named by its hash."""
    here = target()
    return f"{root}/{hashlib.sha256(here.encode()).hexdigest()[:16] if here else 'unknown-cpu'}"


CACHE_ENV = "PARTICLE_ENTROPY_KERNEL_CACHE"  # the machine-wide copies' folder; empty: keep none


def cache_folder() -> Path | None:
    """The machine-wide copy of the module built for ``target()``, which every working directory
    shares (as numba shares its own cache): under $PARTICLE_ENTROPY_KERNEL_CACHE, else
    $XDG_CACHE_HOME or ~/.cache + particle-entropy/kernels, a folder named by the target's hash;
    None where that variable is set empty or the CPU is unknown."""
    here, root = target(), os.environ.get(CACHE_ENV)
    if here is None or root == "":
        return None
    if root is None:
        root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "particle-entropy" / "kernels"
    return Path(root) / hashlib.sha256(here.encode()).hexdigest()[:16]


def _complete(folder: Path) -> bool:
    """Whether ``folder`` holds a module and its TARGET_FILE says it was built for ``target()``."""
    marker = folder / TARGET_FILE
    return marker.is_file() and any(folder.glob(MODULE + ".*")) and marker.read_text() == target()


def provide(folder: str | os.PathLike) -> str:
    """The module for ``target()`` into ``folder``: copied from the machine-wide cache when that
    holds one, else compiled (``build``) and then copied there for the next working directory ->
    "copied" or "built". A cache that cannot be written is left out."""
    import shutil

    folder, cache = Path(folder), cache_folder()
    if cache is not None and _complete(cache):
        folder.mkdir(parents=True, exist_ok=True)
        for f in sorted(cache.glob(MODULE + ".*")) + [cache / TARGET_FILE]:  # the target last, as build
            shutil.copy2(f, folder / f.name)
        return "copied"
    build(folder)
    if cache is not None:
        tmp = cache.with_name(f".{cache.name}.{os.getpid()}.tmp")
        try:
            cache.parent.mkdir(parents=True, exist_ok=True)
            shutil.copytree(folder, tmp)
            os.rename(tmp, cache)  # whole or not at all; another build's copy may have come first
        except OSError:
            shutil.rmtree(tmp, ignore_errors=True)
    return "built"


def use(folder: str | os.PathLike) -> bool:
    """Call the kernels of the module ``build`` wrote to ``folder`` from now on -> whether it was
    taken (built here for this code; else the JIT stays, and a line on stderr says why)."""
    global _loaded
    folder = Path(folder)
    found = sorted(folder.glob(MODULE + ".*"))
    built_for = (folder / TARGET_FILE).read_text() if (folder / TARGET_FILE).exists() else None
    here = target()
    if not found or built_for is None or built_for != here:
        why = "no module" if not found or built_for is None else "built for other code, numba, CPU or settings"
        print(f"compiled kernels in {folder}: {why}; numba's JIT runs them", file=sys.stderr)
        return False
    spec = importlib.util.spec_from_file_location(MODULE, found[0])
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    _loaded = module
    return True


def build(folder: str | os.PathLike) -> Path:
    """Compile every kernel of EXPORTS ahead of time into ``folder`` (numba.pycc) for this CPU, as
    the JIT compiles it -> the module's path. Writes TARGET_FILE beside it last."""
    import inspect
    import warnings

    import numba
    from numba.core import codegen
    from numba.core.registry import cpu_target

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    modules = _kernel_modules()
    jit = cpu_target.target_context.codegen()  # the JIT's target: CPU name and features
    cpu_name, features = jit._get_host_cpu_name(), jit._tm_features
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pycc's deprecation notice
        from numba.pycc import CC

        cc = CC(MODULE)
    cc.output_dir = str(folder)
    cc.verbose = False
    cc.target_cpu = cpu_name
    for name, (mod, signature) in EXPORTS.items():
        kernel = getattr(modules[mod], name)
        params = ", ".join(inspect.signature(kernel.py_func).parameters)
        namespace = {"kernel": kernel}  # a call of the kernel: compiled with the kernel's own flags
        exec(f"def call({params}):\n    return kernel({params})\n", namespace)
        cc.export(name, signature)(namespace["call"])
    aot_features = codegen.AOTCPUCodegen._customize_tm_features
    codegen.AOTCPUCodegen._customize_tm_features = lambda self: features  # pycc's default: the CPU model's
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cc.compile()
    finally:
        codegen.AOTCPUCodegen._customize_tm_features = aot_features
    (folder / TARGET_FILE).write_text(target(numba.__version__) or "")
    return next(folder.glob(MODULE + ".*"))


FAILED_SUFFIX = ".failed"  # beside a target's folder: its build failed here (the JIT runs instead)


def take(root: str | os.PathLike = "results/kernels") -> bool:
    """In a job: use the module for ``target()`` under ``root``, provided once per working
    directory -> whether it was taken. The first job to need it builds or copies it (``provide``)
    while holding a lock, the others wait for that job, then load it. It is provided into a
    temporary folder renamed into place, so a job killed meanwhile leaves nothing half-made. A
    build that fails is said once on stderr and recorded beside the folder: every job then runs
    numba's JIT, slower to start, the same bits (delete the record to try again).

    This is no rule of the workflow on purpose: a Snakemake job whose output an ``ancient`` input
    of every simulation names hides those simulations from the scheduler while it reruns, and the
    run then ends with exit 0 having made none of its targets."""
    import fcntl
    import shutil

    folder = Path(kernels_folder(str(root)))
    failed = folder.with_name(folder.name + FAILED_SUFFIX)
    if not _complete(folder) and not failed.exists():
        folder.parent.mkdir(parents=True, exist_ok=True)
        with open(folder.with_name(f".{folder.name}.lock"), "a") as lock:
            print(f"waiting for the compiled kernels in {folder} ...", file=sys.stderr)
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when this process ends, killed or not
            if not _complete(folder) and not failed.exists():
                tmp = folder.with_name(f".{folder.name}.{os.getpid()}.tmp")
                shutil.rmtree(tmp, ignore_errors=True)
                try:
                    how = provide(tmp)
                    shutil.rmtree(folder, ignore_errors=True)  # a folder of another build, unfinished
                    os.rename(tmp, folder)
                    print(f"{how} the compiled kernels into {folder}", file=sys.stderr)
                except Exception as error:  # no C compiler or Python headers: the JIT runs
                    shutil.rmtree(tmp, ignore_errors=True)
                    failed.write_text(f"{target()}error {type(error).__name__}: {error}\n")
                    print(
                        f"could not compile the kernels ({type(error).__name__}: {error}); "
                        f"every job runs numba's JIT (delete {failed} to try again)",
                        file=sys.stderr,
                    )
    return use(folder)
