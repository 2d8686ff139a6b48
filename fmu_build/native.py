"""Native (C99) builds of the FrictionMount FMU: FMI 2.0 and FMI 3.0, Co-Simulation and
Model Exchange (fmu_build/native_me.py).

``build_native_fmu(fmi=2)`` writes ``dist/FrictionMountNative.fmu`` (FMI 2.0) and
``build_native_fmu(fmi=3)`` ``dist/FrictionMountNative3.fmu`` (FMI 3.0). Both hold the
C port of ``fmu_src/mount_law.py`` (``fmu_src/native/``), need nothing but the C
standard library and libm, and carry their sources so any importer can compile them:

* ``modelDescription.xml`` generated from the one interface table
  (``fmu_src/interface.py``: names, value references, units, descriptions, start values,
  default experiment, capabilities); FMI 3.0 adds the independent variable ``time``
  after the table's value references;
* ``sources/``: the law, the instance (``model.c``), the glue of the FMI version and the
  generated ``model_variables.h`` (variable table and instantiation token); FMI 3.0 also
  ``sources/buildDescription.xml``;
* ``binaries/``: the five :data:`PLATFORMS` (linux64, aarch64-linux, win64, darwin64,
  aarch64-darwin; FMI 3.0: x86_64-linux, aarch64-linux, x86_64-windows, x86_64-darwin,
  aarch64-darwin), cross-compiled in parallel with ``zig cc`` (the ``ziglang``
  package, extra ``native-cross``; flags :data:`CFLAGS`, linux against glibc
  :data:`GLIBC_FLOOR`), win64 with ``x86_64-w64-mingw32-gcc`` where installed; without
  zig linux64 with ``gcc`` and win64 with MinGW only, the others skipped
  (:attr:`NativeBuild.skipped` says why; the one-line compile commands are in
  ``documentation/index.html``, :data:`COMPILE`). Binaries are cached by the hash of
  compiler, command and sources (:func:`cache_folder`).

The archive is reproducible: fixed timestamps, sorted entries, and the GUID /
instantiation token is a hash of everything else. ``null=True`` builds the benchmark's
null FMU (``NullMountNative[3].fmu``): the same interface and bookkeeping, no law.
"""

from __future__ import annotations

import functools
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import uuid
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from drymount.fmu_build import native_me, native_xml
from drymount.fmu_build.extras import fmu_extras
from drymount.fmu_src import interface
from drymount.fmu_src.friction import FRICTION_ELEMENTS
from drymount.fmu_src.mount_law import AXES, LAWS

__all__ = ["CFLAGS", "COMPILE", "NativeBuild", "NativeBuildError", "NativeTarget",
           "build_native_fmu", "default_native_path", "is_native_fmu",
           "variables_header", "write_zip"]

SOURCE_DIR = Path(__file__).resolve().parent.parent / "fmu_src" / "native"
#: The glue of each FMI version: Co-Simulation and shared calls, Model Exchange.
GLUE = {2: ("fmi2_api.h", "fmi2_glue.c", "fmi2_me.c"),
        3: ("fmi3_api.h", "fmi3_glue.c", "fmi3_me.c")}
#: Sources shared by both FMI versions (every file of fmu_src/native but the glue:
#: the law, one file per friction element, the messages, the model), then the glue of
#: each; plus the generated friction_table.h and model_variables.h.
COMMON_SOURCES = tuple(sorted(
    p.name for p in SOURCE_DIR.iterdir() if p.suffix in (".c", ".h")
    and p.name not in {n for g in GLUE.values() for n in g}))
#: Compiler flags of every binary (the issue's warning set; -fPIC only on ELF and
#: Mach-O). -ffp-contract=off: no fused multiply-add (clang would fuse on aarch64), so
#: every platform's binary rounds as the Python law does, operation by operation.
CFLAGS = ("-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2", "-shared",
          "-fvisibility=hidden", "-ffp-contract=off")
#: -s: no debug info (the MinGW runtime's objects carry 244 KB of it). A PE header
#: carries a link time unless told not to (reproducible DLLs): GNU ld's flag, for
#: MinGW only (zig's linker writes no time stamp and refuses the flag: "unsupported
#: linker arg: --no-insert-timestamp").
_PE_FLAGS = ("-s",)
_MINGW_FLAGS = ("-Wl,--no-insert-timestamp",)
#: The oldest glibc the linux binaries need (zig cc links against this version's
#: symbols; tests/test_native_platforms.py reads the versions from the binaries):
#: 2.17 (CentOS/RHEL 7, 2012), below RHEL 8's 2.28.
GLIBC_FLOOR = "2.17"
#: The oldest macOS the darwin binaries load on (zig cc's -target version).
MACOS_FLOOR = "11.0"


@dataclass(frozen=True)
class Platform:
    """How one platform's binary is compiled: with ``zig cc -target <zig>`` (the
    ``ziglang`` package, extra ``native-cross``), or without zig with the C compiler
    ``fallback`` where one is installed (``prefer_fallback``: even with zig, when it
    is installed; the MinGW DLL imports only msvcrt, zig's the UCRT).
    ``fallback_flags``: GNU linker flags only the fallback takes (zig cc 0.17 refuses
    ``--no-insert-timestamp``)."""

    zig: str
    suffix: str
    flags: tuple[str, ...] = ()
    fallback: str | None = None
    prefer_fallback: bool = False
    fallback_flags: tuple[str, ...] = ()  # beside ``flags``, with ``fallback`` only


_LINUX64 = Platform(f"x86_64-linux-gnu.{GLIBC_FLOOR}", ".so", ("-fPIC",), "gcc")
_LINUX_ARM = Platform(f"aarch64-linux-gnu.{GLIBC_FLOOR}", ".so", ("-fPIC",))
_WIN64 = Platform("x86_64-windows-gnu", ".dll", _PE_FLAGS, "x86_64-w64-mingw32-gcc",
                  prefer_fallback=True, fallback_flags=_MINGW_FLAGS)
_DARWIN64 = Platform(f"x86_64-macos.{MACOS_FLOOR}", ".dylib", ("-fPIC",))
_DARWIN_ARM = Platform(f"aarch64-macos.{MACOS_FLOOR}", ".dylib", ("-fPIC",))
#: Platform folder -> how its binary is built, per FMI version (FMI 2.0: its folder
#: names, plus the aarch64 ones fmpy and the Reference-FMUs use; FMI 3.0: the
#: standard's platform tuples).
PLATFORMS = {
    2: {"linux64": _LINUX64, "aarch64-linux": _LINUX_ARM, "win64": _WIN64,
        "darwin64": _DARWIN64, "aarch64-darwin": _DARWIN_ARM},
    3: {"x86_64-linux": _LINUX64, "aarch64-linux": _LINUX_ARM,
        "x86_64-windows": _WIN64, "x86_64-darwin": _DARWIN64,
        "aarch64-darwin": _DARWIN_ARM},
}
#: One-line compile commands for platforms built elsewhere ({id}: model identifier),
#: run in the unzipped FMU's folder.
COMPILE = {
    "linux": "gcc -std=c99 -O2 -fPIC -shared -fvisibility=hidden -o {id}.so "
             "sources/drymount_fmu.c -lm",
    "darwin": "clang -std=c99 -O2 -fPIC -dynamiclib -fvisibility=hidden "
              "-o {id}.dylib sources/drymount_fmu.c -lm",
    "windows (MSVC)": "cl /O2 /LD /Fe{id}.dll sources\\drymount_fmu.c",
    "windows (MinGW)": "x86_64-w64-mingw32-gcc -std=c99 -O2 -shared -o {id}.dll "
                       "sources/drymount_fmu.c -lm",
}

_C_TYPE = {"Real": "MD_REAL", "Integer": "MD_INTEGER", "Boolean": "MD_BOOLEAN"}
#: The per-axis parameter fields model.c stores (md_field): the elastic law's and
#: every field of the registered friction elements (ml_axis_params).
_FIELDS = ("law", "k1", "kc", "k2", "delta", "delta_neg", "c", "friction", "kf",
           "mu", "n0", "sliders", "spread", "fs_ratio", "friction_kind", "theta_deg",
           "k", "kf2", "mu1", "mu2", "preload", "sigma1", "sigma2", "stribeck_ratio",
           "v_stribeck", "maxwell_k1", "maxwell_c1", "maxwell_k2", "maxwell_c2",
           "maxwell_k3", "maxwell_c3", "hyd_Ap", "hyd_C1", "hyd_C2", "hyd_I_i",
           "hyd_R_i", "hyd_I_d", "hyd_R_d")
_AXIS_ROLES = {"u": "MD_INPUT_U", "v": "MD_INPUT_V", "n": "MD_INPUT_N",
               "F": "MD_OUTPUT_F", "Ffr": "MD_OUTPUT_FFR", "kt": "MD_OUTPUT_KT",
               "slip": "MD_OUTPUT_SLIP", "E_fr": "MD_OUTPUT_E_AXIS",
               "w": "MD_LOCAL_W", "N": "MD_OUTPUT_N", "N2": "MD_OUTPUT_N2",
               "slipped": "MD_OUTPUT_SLIPPED", "dE_fr": "MD_OUTPUT_DE_STEP",
               "ks": "MD_OUTPUT_KS",
               "w1": "MD_LOCAL_W1", "w2": "MD_LOCAL_W2"}


class NativeBuildError(RuntimeError):
    """The native FMU could not be built (compiler missing or failing)."""


@dataclass(frozen=True)
class NativeTarget:
    """Which native FMU: FMI version 2 or 3, the real mount or the null model."""

    fmi: int = 2
    null: bool = False

    def __post_init__(self):
        if self.fmi not in GLUE:
            raise ValueError(f"`fmi` must be 2 or 3, got {self.fmi!r}")

    @property
    def model_identifier(self) -> str:
        base = "NullMountNative" if self.null else "FrictionMountNative"
        return base if self.fmi == 2 else base + "3"

    @property
    def file_name(self) -> str:
        return self.model_identifier + ".fmu"


@dataclass(frozen=True)
class NativeBuild:
    """A written native FMU."""

    path: Path
    target: NativeTarget
    token: str
    platforms: tuple[str, ...]        # binaries compiled into the archive
    missing_platforms: tuple[str, ...]  # not compiled (no compiler for them)
    skipped: dict[str, str] = field(default_factory=dict)  # platform -> why

    def summary(self) -> str:
        """Which platforms were built and why any was skipped (one line each)."""
        lines = [f"binaries built: {', '.join(self.platforms)}"]
        lines += [f"skipped {p}: {why} (the sources and compile commands are in the "
                  f"FMU)" for p, why in self.skipped.items()]
        return "\n".join(lines)


def default_native_path(fmi: int = 2) -> Path:
    """``dist/FrictionMountNative.fmu`` (FMI 2.0) or ``dist/FrictionMountNative3.fmu``
    (FMI 3.0) under the current directory (as the PythonFMU build's default)."""
    return Path("dist") / NativeTarget(fmi).file_name


def is_native_fmu(path) -> bool:
    """Whether ``path`` is an existing FMU built by this module (its model identifier
    is one of :class:`NativeTarget`'s). Callers use it so that a native FMU passed as
    ``--fmu`` is used as is, never rebuilt by the PythonFMU builder."""
    import re

    path = Path(path)
    if not path.is_file() or not zipfile.is_zipfile(path):
        return False
    with zipfile.ZipFile(path) as zf:
        try:
            text = zf.read("modelDescription.xml").decode("utf-8", "replace")
        except KeyError:
            return False
    idents = {NativeTarget(f, n).model_identifier for f in GLUE for n in (False, True)}
    found = re.search(r'<CoSimulation[^>]*modelIdentifier="([^"]+)"', text)
    return found is not None and found.group(1) in idents


# ---------------------------------------------------------------------- variables


#: The elastic laws fmu_src/native/mount_law.c implements, in FMU code order.
C_LAWS = ("linear", "cubic", "piecewise", "piecewise_asym")


def _friction_kinds() -> tuple[str, ...]:
    """The registered friction elements, in FMU code order."""
    return tuple(FRICTION_ELEMENTS)


def _check_laws() -> None:
    if LAWS != C_LAWS:
        raise NativeBuildError(
            f"the law registry of fmu_src/mount_law.py has {LAWS}, the C port "
            f"implements {C_LAWS}: port the new laws to fmu_src/native/mount_law.c "
            f"(and its tests) before building the native FMU")
    missing = [n for n, el in FRICTION_ELEMENTS.items() if el.c_port is None]
    if missing:
        raise NativeBuildError(
            f"the friction elements {missing} have no C port (FrictionElement.c_port): "
            f"write fmu_src/native/<element>.c defining its ml_element before "
            f"building the native FMU")


def friction_table_header() -> str:
    """``friction_table.h``: the C elements in registry order (FMU codes), generated
    from ``fmu_src.friction_elements`` (each element's ``c_port``)."""
    ports = [el.c_port for el in FRICTION_ELEMENTS.values()]
    return ("/* Generated by fmu_build/native.py from fmu_src/friction_elements.py: "
            "do not edit. */\n#ifndef DRYMOUNT_FRICTION_TABLE_H\n"
            "#define DRYMOUNT_FRICTION_TABLE_H\n\n#include \"mount_law.h\"\n\n"
            f"#define ML_N_FRICTION_KINDS {len(ports)}\n"
            + "".join(f"ML_ELEMENT_DECL const ml_element {c};\n" for c in ports)
            + "static const ml_element *const ML_ELEMENTS[ML_N_FRICTION_KINDS] = {"
            + ", ".join(f"&{c}" for c in ports) + "};\n\n#endif\n")


#: The generated translation unit the binaries are compiled from (internal.h).
UNITY = "drymount_fmu.c"


def unity_source(target: NativeTarget) -> str:
    """``drymount_fmu.c``: every .c file of the FMU #included into one translation
    unit with DRYMOUNT_UNITY defined, so that every internal function is static and
    only the fmi2* / fmi3* functions have external linkage."""
    c_files = [n for n in (*COMMON_SOURCES, *GLUE[target.fmi]) if n.endswith(".c")]
    return ("/* Generated by fmu_build/native.py: the whole FMU as one translation "
            "unit (see internal.h).\n * Compile this file alone; define "
            f"FMI{target.fmi}_FUNCTION_PREFIX to prefix the FMI functions. */\n"
            "#define DRYMOUNT_UNITY 1\n"
            + "".join(f'#include "{n}"\n' for n in c_files))


def write_law_sources(folder) -> list[Path]:
    """Write the C law (every shared source and friction_table.h) into ``folder``;
    returns its .c files (for tests that compile the law alone)."""
    folder = Path(folder)
    for name in COMMON_SOURCES:
        (folder / name).write_bytes((SOURCE_DIR / name).read_bytes())
    (folder / "friction_table.h").write_text(friction_table_header())
    # not the instance, its variables, its FMU state, its Model Exchange
    return [folder / n for n in COMMON_SOURCES if n.endswith(".c")
            and n not in ("model.c", "model_vars.c", "model_state.c", "me.c",
                            "me_bank.c")]


def _variables(target: NativeTarget) -> list[tuple[int, interface.Variable]]:
    """(value reference, variable) of the FMU: the table, plus ``time`` in FMI 3.0."""
    out = list(enumerate(interface.VARIABLES))
    if target.fmi == 3:
        out.append((len(out), interface.Variable(
            "time", "Real", "independent", "continuous", None, "s",
            "simulation time")))
    out += [(len(out) + i, var) for i, var in enumerate(native_me.me_variables())]
    return out


def _role(var: interface.Variable) -> tuple[str, int, str]:
    """(C role, axis index, parameter field) of a table variable; ValueError if the
    native model does not implement it."""
    if var.causality == "independent":
        return "MD_TIME", -1, "MD_P_NONE"
    me = native_me.me_role(var.name)
    if me is not None:
        return me[0], me[1], "MD_P_NONE"
    if var.name == "E_fr":
        return "MD_OUTPUT_E_TOTAL", -1, "MD_P_NONE"
    for j, axis in enumerate(AXES):
        field = var.name[len(axis) + 1:]
        if var.causality == "parameter" and var.name.startswith(axis + "_") \
                and field in _FIELDS:
            return "MD_PARAMETER", j, "MD_P_" + field.upper()
        prefix, _, suffix = var.name.rpartition("_")
        if suffix == axis and prefix in _AXIS_ROLES:
            return _AXIS_ROLES[prefix], j, "MD_P_NONE"
    raise ValueError(f"the native FMU does not implement the interface variable "
                     f"{var.name!r} (causality {var.causality}); extend "
                     f"fmu_src/native/model.c and fmu_build/native.py")


def _c_double(value) -> str:
    return repr(float(0.0 if value is None else value))


def variables_header(target: NativeTarget, token: str) -> str:
    """``model_variables.h``: the variable table of the C model and its token."""
    rows = []
    for vr, var in _variables(target):
        role, axis, field = _role(var)
        rows.append(f'    {{"{var.name}", {_C_TYPE[var.type]}, {role}, {axis}, '
                    f'{field}, {_c_double(var.start)}}}, /* vr {vr} */')
    null = "#define DRYMOUNT_NULL_MODEL 1\n" if target.null else ""
    return (
        "/* Generated by fmu_build/native.py from fmu_src/interface.py: "
        "do not edit. */\n"
        "#ifndef DRYMOUNT_MODEL_VARIABLES_H\n#define DRYMOUNT_MODEL_VARIABLES_H\n\n"
        '#include "model.h"\n\n' + null
        + f'#define MD_INSTANTIATION_TOKEN "{token}"\n'
        + f"#define MD_N_VARIABLES {len(rows)}u\n\n"
        + "static const md_variable MD_VARIABLES[MD_N_VARIABLES] = {\n"
        + "\n".join(rows) + "\n};\n\n#endif\n")


def model_description(target: NativeTarget, token: str) -> bytes:
    """``modelDescription.xml`` of the FMI 2.0 or FMI 3.0 flavour
    (:mod:`fmu_build.native_xml`)."""
    return native_xml.model_description(target, token, _variables(target), UNITY)


def build_description(target: NativeTarget) -> bytes:
    """``sources/buildDescription.xml`` (FMI 3.0)."""
    return native_xml.build_description(target.model_identifier, UNITY)


# ---------------------------------------------------------------------- archive


def _source_names(target: NativeTarget) -> list[str]:
    return sorted([*COMMON_SOURCES, *GLUE[target.fmi], "model_variables.h",
                   "friction_table.h", UNITY])


def _sources(target: NativeTarget, token: str) -> dict[str, bytes]:
    out = {name: (SOURCE_DIR / name).read_bytes()
           for name in (*COMMON_SOURCES, *GLUE[target.fmi])}
    out["model_variables.h"] = variables_header(target, token).encode()
    out["friction_table.h"] = friction_table_header().encode()
    out[UNITY] = unity_source(target).encode()
    return out


def _token(target: NativeTarget) -> str:
    """GUID / instantiation token: a hash of the sources and the model description
    written with a placeholder token."""
    h = hashlib.sha256()
    for name, data in sorted(_sources(target, "{TOKEN}").items()):
        h.update(name.encode() + b"\0" + data + b"\0")
    h.update(model_description(target, "{TOKEN}"))
    return "{" + str(uuid.UUID(bytes=h.digest()[:16])) + "}"


@dataclass(frozen=True)
class _Job:
    """One platform's compile: the command, the library it writes, its cache key."""

    platform: str
    cmd: tuple[str, ...]
    out: Path
    key: str


def _zig_command() -> tuple[str, ...] | None:
    """``python -m ziglang`` if the ``ziglang`` package is installed, else None."""
    import importlib.util

    if importlib.util.find_spec("ziglang") is None:
        return None
    return (sys.executable, "-m", "ziglang")


@functools.cache
def _compiler_identity(cmd: tuple[str, ...]) -> str:
    """The compiler's version text (part of the cache key)."""
    probe = [*cmd[:3], "version"] if cmd[1:3] == ("-m", "ziglang") else [cmd[0],
                                                                        "--version"]
    proc = subprocess.run(probe, capture_output=True, text=True, check=False)
    return proc.stdout.strip() + proc.stderr.strip()


def _compiler(plat: Platform) -> tuple[tuple[str, ...] | None, str]:
    """(compiler command, "") for ``plat``, or (None, why it cannot be built)."""
    zig = _zig_command()
    fallback = plat.fallback if plat.fallback and shutil.which(plat.fallback) else None
    if fallback is not None and (plat.prefer_fallback or zig is None):
        return (fallback,), ""
    if zig is not None:
        return (*zig, "cc", "-target", plat.zig), ""
    needs = "zig cc (pip install 'drymount[native-cross]')"
    return None, needs + (f" or {plat.fallback}" if plat.fallback else "")


def cache_folder() -> Path | None:
    """Where compiled binaries are kept by source hash: ``$DRYMOUNT_NATIVE_CACHE``
    (empty: no cache), else ``~/.cache/drymount/native`` (``$XDG_CACHE_HOME``)."""
    env = os.environ.get("DRYMOUNT_NATIVE_CACHE")
    if env is not None:
        return Path(env) if env else None
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "drymount" / "native"


def debug_cflags() -> tuple[str, ...]:
    """``$DRYMOUNT_NATIVE_CFLAGS`` split (debugging only, e.g. ``-fsanitize=address
    -fno-omit-frame-pointer -g``): added to the host's binary (compiled with gcc then,
    not stripped) and to the C stepping loop (vehicle/c_loop.py); () when unset."""
    return tuple(os.environ.get("DRYMOUNT_NATIVE_CFLAGS", "").split())


def _job(target: NativeTarget, folder: Path, platform: str,
         sources: dict[str, bytes]) -> _Job | str:
    """The compile of ``platform`` in ``folder``, or why it cannot be built."""
    plat = PLATFORMS[target.fmi][platform]
    debug = debug_cflags() if platform == next(iter(PLATFORMS[target.fmi])) else ()
    compiler, why = _compiler(plat)
    if debug and plat.fallback and shutil.which(plat.fallback):
        compiler = (plat.fallback,)  # zig cc has no AddressSanitizer
    if compiler is None:
        return why
    out = folder / platform / (target.model_identifier + plat.suffix)
    # relative names in the build folder: no temporary path ends up in the binary
    c_files = [UNITY]
    flags = plat.flags + (plat.fallback_flags if compiler == (plat.fallback,) else ())
    flags += debug
    strip = () if "-s" in flags or debug else ("-s",)
    cmd = (*compiler, *CFLAGS, *flags, *strip, "-o",
           f"{platform}/{out.name}", *c_files, "-lm")
    h = hashlib.sha256(_compiler_identity(compiler).encode() + b"\0")
    h.update("\0".join(cmd).encode())
    for name, data in sorted(sources.items()):
        h.update(name.encode() + b"\0" + data + b"\0")
    return _Job(platform, cmd, out, h.hexdigest())


def _run_jobs(jobs: list[_Job], folder: Path) -> None:
    """Run the compiles not in the cache in parallel; NativeBuildError on a failure."""
    cache = cache_folder()
    running = []
    for job in jobs:
        hit = cache / job.key if cache is not None else None
        job.out.parent.mkdir(parents=True, exist_ok=True)
        if hit is not None and hit.is_file():
            shutil.copyfile(hit, job.out)
            continue
        proc = subprocess.Popen(job.cmd, cwd=folder, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        running.append((job, proc, hit))
    failed = []
    for job, proc, hit in running:
        _, err = proc.communicate()
        if proc.returncode != 0:
            failed.append(f"{' '.join(job.cmd)} failed:\n{err}")
        elif hit is not None:
            hit.parent.mkdir(parents=True, exist_ok=True)
            tmp = hit.with_name(f"{hit.name}.{os.getpid()}.partial")
            shutil.copyfile(job.out, tmp)
            tmp.replace(hit)
    if failed:
        raise NativeBuildError("\n".join(failed))


def compile_binaries(target: NativeTarget, folder: Path,
                     sources: dict[str, bytes]) -> tuple[dict[str, Path],
                                                         dict[str, str]]:
    """Compile every platform's binary of ``target`` from ``sources`` (written into
    ``folder``) in parallel: ({platform: library}, {skipped platform: why})."""
    for name, data in sources.items():
        (folder / name).write_bytes(data)
    jobs, skipped = [], {}
    for platform in PLATFORMS[target.fmi]:
        job = _job(target, folder, platform, sources)
        if isinstance(job, str):
            skipped[platform] = f"no compiler: needs {job}"
        else:
            jobs.append(job)
    host = next(iter(PLATFORMS[target.fmi]))
    if host in skipped:
        raise NativeBuildError("gcc or zig cc is required to build the native FMU "
                               "(apt-get install gcc, or pip install "
                               "'drymount[native-cross]')")
    _run_jobs(jobs, folder)
    return {job.platform: job.out for job in jobs}, skipped


def _documentation(target: NativeTarget, skipped: dict[str, str]) -> bytes:
    ident = target.model_identifier
    rows = "\n".join(f"<tr><td>{p}</td><td><code>{c.format(id=ident)}</code></td></tr>"
                     for p, c in COMPILE.items())
    built = [p for p in PLATFORMS[target.fmi] if p not in skipped]
    floors = (f"<p>Binaries: {', '.join(built)}. The linux ones need glibc >= "
              f"{GLIBC_FLOOR}, the darwin ones macOS >= {MACOS_FLOOR}.</p>")
    missing_text = (f"<p>Not compiled into this archive: {', '.join(skipped)} (no "
                    f"cross compiler on the build machine); use the commands below."
                    f"</p>" if skipped else "")
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{ident}</title></head><body>
<h1>{ident}: friction-damped engine mount (FMI {target.fmi}.0 Co-Simulation and Model
Exchange, C)</h1>
<p>The native build of drymount's FrictionMount FMU: the same variables, units, start
values and default experiment as the PythonFMU build (FrictionMount.fmu), the mount law
ported to C99. It needs only the C standard library and libm: no Python.</p>
<p>Variables per axis (axial, radial1, radial2): parameters &lt;axis&gt;_law, _k1, _kc,
_k2, _delta, _delta_neg, _c, _friction, _friction_kind and the fields of the friction
elements (as in the PythonFMU build); inputs u_, v_, n_; outputs F_, Ffr_, kt_,
slip_, E_fr_, N_, N2_ and, about the step just taken, slipped_, dE_fr_, ks_; the
output E_fr and the locals w_ (slider positions, settable also between steps, as in
the PythonFMU build).</p>
{floors}
{missing_text}
<h2>Compiling the sources for another platform</h2>
<p>Run in the folder of the unzipped FMU, then put the library into
<code>binaries/&lt;platform&gt;/</code> (one of
{", ".join(PLATFORMS[target.fmi])}) and zip the folder again.</p>
<table>{rows}</table>
</body></html>
""".encode()


def write_zip(path: Path, files: dict[str, bytes],
              first: str = "modelDescription.xml") -> None:
    """Reproducible archive (FMU, SSP): ``first`` first, the rest sorted, fixed
    timestamps and permissions; written to a temporary name and moved."""
    names = [first] + sorted(n for n in files if n != first)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".partial")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        for name in names:
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            zf.writestr(info, files[name])
    tmp.replace(path)


def build_native_fmu(dest=None, *, fmi: int = 2, null: bool = False) -> NativeBuild:
    """Build the native FMU of FMI version ``fmi`` (2 or 3) into ``dest`` (default
    ``dist/<model identifier>.fmu``) and return what was written."""
    target = NativeTarget(fmi, null)
    _check_laws()
    path = Path(dest) if dest is not None else Path("dist") / target.file_name
    token = _token(target)
    sources = _sources(target, token)
    files = {"modelDescription.xml": model_description(target, token)}
    files.update({f"sources/{n}": data for n, data in sources.items()})
    if fmi == 3:
        files["sources/buildDescription.xml"] = build_description(target)
    with tempfile.TemporaryDirectory(prefix="drymount-native-") as tmp:
        libs, skipped = compile_binaries(target, Path(tmp), sources)
        for platform, lib in libs.items():
            files[f"binaries/{platform}/{lib.name}"] = lib.read_bytes()
    files["documentation/index.html"] = _documentation(target, skipped)
    files.update(fmu_extras())  # licence, FMI-LS-REF reference experiment
    write_zip(path, files)
    return NativeBuild(path, target, token, tuple(libs), tuple(skipped),
                       skipped)
