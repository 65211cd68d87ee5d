"""The compiled kernels a simulation calls: numba's JIT, or the same kernels compiled ahead of time.

Callers reach every numba kernel of the symmetric MTPT transfer, the kernel reconstructions, the
finite differences and the authors' sequential loop through ``kernels()``, by the names of
``EXPORTS``. By default that is numba's JIT: the kernels are compiled, or loaded from numba's
on-disk cache, on first call, and a process pays for numba itself first (import 0.15 s, target
set-up 0.3 s, which also imports scipy.linalg), more than a small job's whole run.

A simulation job instead calls ``take()``, which loads (``use``) a module that ``build``
compiled ahead of time from the same kernels (the first job that needs it builds it, once per
code version and target, or copies it from this user's cache), and so imports no numba at all.
Its results are the same bits as the JIT's: the build hands LLVM the target the JIT would (this
CPU's name and features, numba's settings), each kernel keeps its own flags (fastmath where it
has them), and each is exported with the one signature runs call it with. ``use`` takes the
module only if it was built from this code, by this numba, for this CPU and numba settings
(``target()``); else the job runs the JIT as before.
"""

from __future__ import annotations

import errno
import functools
import hashlib
import importlib.machinery
import importlib.util
import json
import os
import stat
import sys
import types
from pathlib import Path

MODULE = "particle_entropy_kernels"  # the extension module's name (its init function's)
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
    "gt_solve": ("thomas", "f8[::1](f8[::1], f8[::1], f8[::1], f8[::1], i4[::1], f8[::1])"),
    "tvd_advect": ("thomas", "Tuple((f8[::1], f8))(f8[::1], f8)"),
    "stencil_apply": ("stencil2d", "f8[:, ::1](f8[:, ::1], f8[:, ::1])"),
    "bicgstab": ("stencil2d", "Tuple((f8[:, ::1], i8, f8))(f8[:, ::1], f8[:, ::1], f8, i8, f8[:, ::1])"),
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
    from . import gauss_kernels, sequential_kernels, stencil2d, thomas, transfer_kernels

    return {
        "gauss_kernels": gauss_kernels,
        "stencil2d": stencil2d,
        "transfer_kernels": transfer_kernels,
        "thomas": thomas,
        "sequential_kernels": sequential_kernels,
    }


def code_key() -> str:
    """SHA-256 of the kernels' code: this module, the kernel modules and what they import."""
    digest = hashlib.sha256()
    kernel_files = ("gauss_kernels.py", "transfer_kernels.py", "thomas.py", "stencil2d.py", "sequential_kernels.py")
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


def target_key() -> str:
    """``target()`` in short: the first 16 hex digits of its SHA-256 ("unknown-cpu" where the CPU is
    unknown). It names the machine-wide cache's folder and the run's (``kernels_folder``); it is no
    input of a simulation (its results are the JIT's bits on any target)."""
    here = target()
    return hashlib.sha256(here.encode()).hexdigest()[:16] if here else "unknown-cpu"


def kernels_folder(root: str = "results/kernels") -> str:
    """A folder of ``root`` named ``target_key()``, for a module built for ``target()``."""
    return f"{root}/{target_key()}"


CACHE_ENV = "PARTICLE_ENTROPY_KERNEL_CACHE"  # the machine-wide copies' folder; empty: keep none
RECORD = "module.json"  # beside the module, written last: its one file name, SHA-256 and target()
IDENTITY = "code_key_words"  # a function of the module: the code_key() it was built from, in 8 words


def cache_folder() -> Path | None:
    """The machine-wide copy of the module built for ``target()``, which every working directory
    of this user shares (as numba shares its own cache): under $PARTICLE_ENTROPY_KERNEL_CACHE, else
    $XDG_CACHE_HOME or ~/.cache + particle-entropy/kernels, a folder named ``target_key()``;
    None where that variable is set empty, the CPU is unknown or the user has no home folder."""
    root = os.environ.get(CACHE_ENV)
    if target() is None or root == "":
        return None
    if root is None:
        try:
            home = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
        except RuntimeError:  # no HOME and no passwd entry: keep no machine-wide copy
            return None
        root = Path(home) / "particle-entropy" / "kernels"
    return Path(root) / target_key()


def _module_names() -> set[str]:
    """The file names a module of this Python may have (loaded as an extension, never as source)."""
    return {MODULE + suffix for suffix in importlib.machinery.EXTENSION_SUFFIXES}


def _words(key: str) -> tuple[int, ...]:
    return tuple(int(key[i : i + 8], 16) for i in range(0, len(key), 8))


def _complete(folder: str | os.PathLike) -> bool:
    """Whether ``folder`` holds a module built for ``target()`` whose SHA-256 is the one recorded."""
    folder = Path(folder)
    try:
        _verified((folder / RECORD).read_bytes(), lambda name: (folder / name).read_bytes())
    except (OSError, _Refused):
        return False
    return True


def _verified(record: bytes | str, read) -> tuple[str, bytes]:
    """The module a record names, read by ``read(name)`` -> (its file name, its bytes), checked
    against the record: built for ``target()``, a module file name, its SHA-256; else
    _Refused, saying why."""
    try:
        entry = json.loads(record)
        name, digest, built_for = entry["module"], entry["sha256"], entry["target"]
    except (ValueError, KeyError, TypeError):
        raise _Refused("its record is unreadable") from None
    if built_for != target():
        raise _Refused("built for other code, numba, CPU or settings")
    if name not in _module_names():
        raise _Refused(f"its record names no module file ({name!r})")
    try:
        data = read(name)
    except OSError as e:
        raise _Refused(f"its module cannot be read ({e.strerror or e})") from None
    if hashlib.sha256(data).hexdigest() != digest:
        raise _Refused("its module fails the SHA-256 its build recorded (corrupt or replaced)")
    return name, data


class _Refused(Exception):
    """A module or a cache folder that is not taken; the message says why, in a few words."""


def _problem(st: os.stat_result) -> str | None:
    """Why a file or folder cannot be trusted (as ssh treats its keys): another owner, or one that
    others may write; None if this user owns it and no one else can write it."""
    if st.st_uid != os.getuid():
        return f"belongs to uid {st.st_uid}, not to this user ({os.getuid()})"
    if st.st_mode & 0o022:
        return f"can be written by others (mode {stat.S_IMODE(st.st_mode):o})"
    return None


def _read_at(dir_fd: int, name: str) -> bytes:
    """The bytes of file ``name`` of an open folder: a regular file (no link followed) that only
    this user can write; else _Refused."""
    fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW, dir_fd=dir_fd)
    with os.fdopen(fd, "rb") as f:
        st = os.fstat(f.fileno())
        why = "is no regular file" if not stat.S_ISREG(st.st_mode) else _problem(st)
        if why:
            raise _Refused(f"its {name} {why}")
        return f.read()


def _from_cache(cache: Path) -> tuple[str, str | None, tuple[str, bytes, bytes] | None]:
    """What the cache folder holds for ``target()``: ("absent" | "untrusted" | "stale" | "sound",
    why not sound, (module name, its bytes, the record) if sound). A folder is read only if it is
    no link, this user owns it and no one else can write it; its files are read through the one
    open folder, so nothing can be swapped in between. A folder of this user that is no longer
    sound (corrupt, another target, writable by others) is "stale": replaced, never read."""
    try:
        fd = os.open(cache, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
    except FileNotFoundError:
        return "absent", None, None
    except OSError as e:
        why = "is no folder" if e.errno in (errno.ELOOP, errno.ENOTDIR) else f"cannot be opened ({e.strerror})"
        return "untrusted", "is a symbolic link" if cache.is_symlink() else why, None
    try:
        st = os.fstat(fd)
        if st.st_uid != os.getuid():
            return "untrusted", _problem(st), None
        if why := _problem(st):
            return "stale", why, None
        record = _read_at(fd, RECORD)
        name, data = _verified(record, lambda name: _read_at(fd, name))
        return "sound", None, (name, data, record)
    except FileNotFoundError:
        return "stale", "holds no complete module", None
    except (_Refused, OSError) as e:
        return "stale", str(e), None
    finally:
        os.close(fd)


def _write(path: Path, data: bytes, mode: int) -> None:
    """``data`` into ``path`` whole or not at all (a new file renamed over it)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.unlink(missing_ok=True)
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, mode)
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def _install(folder: Path, name: str, data: bytes, record: bytes) -> None:
    """A module and its record into ``folder``: the record last, as build writes them."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / RECORD).unlink(missing_ok=True)
    _write(folder / name, data, 0o644)
    _write(folder / RECORD, record, 0o644)


def _private_folders(path: Path) -> None:
    """``path`` and its missing parents, each made readable and writable by this user alone
    (mode 0o700 whatever the umask)."""
    missing = []
    while not os.path.lexists(path):
        missing.append(path)
        path = path.parent
    for folder in reversed(missing):
        try:
            os.mkdir(folder, 0o700)
        except FileExistsError:
            pass


def _publish(cache: Path, folder: Path, replace: bool) -> None:
    """The module ``folder`` holds, checked again, into the cache folder: a private folder (0o700,
    its files 0o600) renamed into place whole, in place of a stale one of this user's if
    ``replace``. Another build's copy may come first; a cache that cannot be written is left out."""
    import shutil

    try:
        record = (folder / RECORD).read_bytes()
        name, data = _verified(record, lambda name: (folder / name).read_bytes())
    except (OSError, _Refused):
        return
    tmp = cache.with_name(f".{cache.name}.{os.getpid()}.tmp")
    old = cache.with_name(f".{cache.name}.{os.getpid()}.old")
    try:
        _private_folders(cache.parent)
        shutil.rmtree(tmp, ignore_errors=True)
        os.mkdir(tmp, 0o700)
        _write(tmp / name, data, 0o600)
        _write(tmp / RECORD, record, 0o600)
        if replace:
            os.rename(cache, old)
        os.rename(tmp, cache)
    except OSError:
        pass
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        shutil.rmtree(old, ignore_errors=True)


def provide(folder: str | os.PathLike) -> str:
    """The module for ``target()`` into ``folder``: copied from the machine-wide cache when that
    holds a sound one (``_from_cache``), else compiled (``build``) and then copied there for the
    next working directory -> "copied" or "built". A cache folder that is not taken is named on
    stderr in one line, with why; one that cannot be written is left out."""
    folder, cache = Path(folder), cache_folder()
    state, why, found = _from_cache(cache) if cache is not None else ("none", None, None)
    if found is not None:
        _install(folder, *found)
        return "copied"
    build(folder)
    if state in ("absent", "stale"):
        _publish(cache, folder, replace=state == "stale")
    if why:
        done = "replaced the cache's copy" if state == "stale" else "left the cache alone"
        print(f"kernel cache {cache}: {why}; built the kernels in {folder} and {done}", file=sys.stderr)
    return "built"


def use(folder: str | os.PathLike) -> bool:
    """Call the kernels of the module ``build`` wrote to ``folder`` from now on -> whether it was
    taken; else the JIT stays, and a line on stderr says why. Taken is the one file its record
    names, if built for ``target()`` and of the SHA-256 recorded, and once loaded, if it says it
    was built from this code (IDENTITY)."""
    global _loaded
    folder = Path(folder)
    try:
        try:
            record = (folder / RECORD).read_bytes()
        except OSError:
            raise _Refused("no module") from None
        name, _ = _verified(record, lambda name: (folder / name).read_bytes())
        try:
            spec = importlib.util.spec_from_file_location(MODULE, folder / name)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            built_from = tuple(getattr(module, IDENTITY)())
        except Exception as e:  # noqa: BLE001 - any failure to load leaves the JIT
            first = (str(e).splitlines() or [""])[0]
            raise _Refused(f"its module does not load ({type(e).__name__}: {first})") from None
        if built_from != _words(code_key()):
            raise _Refused("its module was built from other code")
    except _Refused as e:
        print(f"compiled kernels in {folder}: {e}; numba's JIT runs them", file=sys.stderr)
        return False
    _loaded = module
    return True


def build(folder: str | os.PathLike) -> Path:
    """Compile every kernel of EXPORTS ahead of time into ``folder`` (numba.pycc) for this CPU, as
    the JIT compiles it -> the module's path. The module also exports IDENTITY, the code_key() it
    is built from; RECORD is written beside it last (its file name, SHA-256 and target())."""
    import inspect
    import warnings

    import numba
    from numba.core import codegen
    from numba.core.registry import cpu_target

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / RECORD).unlink(missing_ok=True)  # no record until the module is whole
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
    words = _words(code_key())
    exec(f"def identity():\n    return {words!r}\n", namespace)
    cc.export(IDENTITY, f"UniTuple(i8, {len(words)})()")(namespace["identity"])
    aot_features = codegen.AOTCPUCodegen._customize_tm_features
    codegen.AOTCPUCodegen._customize_tm_features = lambda self: features  # pycc's default: the CPU model's
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cc.compile()
    finally:
        codegen.AOTCPUCodegen._customize_tm_features = aot_features
    module = folder / Path(cc.output_file).name  # the one file this build wrote
    digest = hashlib.sha256(module.read_bytes()).hexdigest()
    record = {"module": module.name, "sha256": digest, "target": target(numba.__version__) or ""}
    _write(folder / RECORD, json.dumps(record, indent=1).encode(), 0o644)
    return module


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
    import socket

    folder = Path(kernels_folder(str(root)))
    if target() is None:  # no CPU to build for (no /proc/cpuinfo): nothing could ever be taken
        print("compiled kernels: this CPU is unknown; numba's JIT runs them", file=sys.stderr)
        return False
    failed = folder.with_name(folder.name + FAILED_SUFFIX)
    if not _complete(folder) and not failed.exists():
        _private_run_folder(folder.parent)
        with open(folder.with_name(f".{folder.name}.lock"), "a") as lock:
            print(f"waiting for the compiled kernels in {folder} ...", file=sys.stderr)
            try:
                fcntl.flock(lock, fcntl.LOCK_EX)  # released when this process ends, killed or not
                locked = True
            except OSError as error:  # a file system without locks (ENOSYS, ENOLCK): build aside
                print(f"no file lock in {folder.parent} ({error.strerror}): building without one", file=sys.stderr)
                locked = False
            if not _complete(folder) and not failed.exists():
                if locked:  # what a job killed while building left (no other builds it: we hold the lock)
                    for left in folder.parent.glob(f".{folder.name}.*.tmp"):
                        shutil.rmtree(left, ignore_errors=True)
                tmp = folder.with_name(f".{folder.name}.{socket.gethostname()}-{os.getpid()}.tmp")
                _provide_into(folder, tmp, failed)
    return use(folder)


def _private_run_folder(path: Path) -> None:
    """``path`` made, writable by this user alone whatever the umask (others may read it)."""
    path.mkdir(parents=True, exist_ok=True)
    if path.stat().st_mode & 0o022 and path.stat().st_uid == os.getuid():
        path.chmod(0o755)


def _provide_into(folder: Path, tmp: Path, failed: Path) -> None:
    """``provide`` into ``tmp``, then renamed to ``folder`` whole; a failure recorded in ``failed``."""
    import shutil

    try:
        how = provide(tmp)
        tmp.chmod(0o755)
        shutil.rmtree(folder, ignore_errors=True)  # a folder of another build, unfinished or corrupt
        os.rename(tmp, folder)
        print(f"{how} the compiled kernels into {folder}", file=sys.stderr)
    except Exception as error:  # no C compiler or Python headers: the JIT runs
        shutil.rmtree(tmp, ignore_errors=True)
        try:
            failed.write_text(f"{target()}error {type(error).__name__}: {error}\n")
            again = f" (delete {failed} to try again)"
        except OSError:  # the record itself cannot be written: the next job tries again
            again = ""
        print(
            f"could not compile the kernels ({type(error).__name__}: {error}); numba's JIT runs them{again}",
            file=sys.stderr,
        )
