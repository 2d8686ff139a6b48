"""The native FMUs' cross-compiled binaries (fmu_build/native.py, issue 30 item 1).

* aarch64-linux: the FMI 2.0 binary runs under ``qemu-aarch64`` in the plain C host
  (tests/c_host/native_host.c, itself cross-compiled with ``zig cc``) and its outputs
  equal the linux64 binary's in the same host bit for bit on random trajectories;
* darwin64 / x86_64-darwin and aarch64-darwin: Mach-O dylibs of the right CPU type
  whose exported symbols (read from the Mach-O symbol table here) are exactly the
  functions the FMI header of the sources declares;
* linux64 and aarch64-linux: the highest glibc symbol version they need (read from
  the ELF version-needs section with ``readelf``) is at most GLIBC_FLOOR (2.17);
* win64: the DLL in the C host under wine (skipped where wine is missing).

Skips name what is missing (zig, qemu-user, the aarch64 C library, wine).
"""

from __future__ import annotations

import re
import shutil
import struct
import zipfile
from pathlib import Path

import numpy as np
import pytest
from native_helpers import (
    GENERAL_LAYOUT,
    LAW_LAYOUT,
    ROOT,
    build,
    host_config,
    random_general_instance,
    random_instance,
    random_trajectory,
    run,
)

from drymount.fmu_build import native

fmpy = pytest.importorskip("fmpy", reason="pip install -e .[fmu] installs fmpy")

H = 1e-4
STEPS = 20_000
AARCH64_SYSROOT = Path("/usr/aarch64-linux-gnu")  # Debian's libc6-arm64-cross
WINE64_DEBIAN = Path("/usr/lib/wine/wine64")  # Debian's wine64 without the wine package
IDENT = {2: "FrictionMountNative", 3: "FrictionMountNative3"}
#: Mach-O CPU types (mach/machine.h): CPU_TYPE_X86_64, CPU_TYPE_ARM64.
CPU_X86_64, CPU_ARM64 = 0x01000007, 0x0100000C
DARWIN = {2: {"darwin64": CPU_X86_64, "aarch64-darwin": CPU_ARM64},
          3: {"x86_64-darwin": CPU_X86_64, "aarch64-darwin": CPU_ARM64}}
#: What the linker defines in every dylib (the Mach-O header, the C runtime's
#: handle), beside the code's exports.
LINKER_SYMBOLS = {"_mh_dylib_header", "__dso_handle"}
LINUX = {2: ("linux64", "aarch64-linux"), 3: ("x86_64-linux", "aarch64-linux")}


def need_zig():
    if native._zig_command() is None:
        pytest.skip("zig cc cross-compiles these binaries: pip install "
                    "'drymount[native-cross]'")


@pytest.fixture(scope="module", params=[2, 3], ids=["fmi2", "fmi3"])
def fmu(request, tmp_path_factory):
    need_zig()
    return request.param, build(tmp_path_factory.mktemp("plat"), request.param)


def _binary(path: Path, platform: str, suffix: str) -> bytes:
    ident = IDENT[2] if "Native3" not in zipfile.ZipFile(path).read(
        "modelDescription.xml").decode() else IDENT[3]
    return zipfile.ZipFile(path).read(f"binaries/{platform}/{ident}{suffix}")


def test_every_platform_is_built(fmu):
    fmi, path = fmu
    names = set(zipfile.ZipFile(path).namelist())
    suffix = {".so", ".dll", ".dylib"}
    built = {n.split("/")[1] for n in names if n.startswith("binaries/")
             and Path(n).suffix in suffix}
    assert built == set(native.PLATFORMS[fmi])


# ---------------------------------------------------------------------- Mach-O


def macho_exports(data: bytes) -> tuple[int, int, set[str]]:
    """(cpu type, file type, names of the defined external symbols without the
    leading underscore) of a thin 64-bit little-endian Mach-O image, from its
    LC_SYMTAB (mach-o/loader.h, mach-o/nlist.h)."""
    magic, cpu, _sub, filetype, ncmds, _size, _flags, _res = struct.unpack_from(
        "<IiiIIIII", data, 0)
    assert magic == 0xFEEDFACF, f"not a 64-bit Mach-O image (magic {magic:#x})"
    offset, symtab = 32, None
    for _ in range(ncmds):
        cmd, cmdsize = struct.unpack_from("<II", data, offset)
        if cmd == 0x2:  # LC_SYMTAB
            symtab = struct.unpack_from("<IIII", data, offset + 8)
        offset += cmdsize
    assert symtab is not None, "no LC_SYMTAB"
    symoff, nsyms, stroff, _strsize = symtab
    names = set()
    for i in range(nsyms):
        strx, n_type, _sect, _desc, _value = struct.unpack_from(
            "<IBBHQ", data, symoff + 16 * i)
        if n_type & 0xE0:  # a debugging (stab) entry
            continue
        if n_type & 0x01 and (n_type & 0x0E) == 0x0E:  # N_EXT, N_SECT: defined
            end = data.index(b"\0", stroff + strx)
            names.add(data[stroff + strx:end].decode().removeprefix("_"))
    return cpu, filetype, names


def elf_exports(lib: Path) -> set[str]:
    """The defined dynamic symbols of an ELF shared object (nm -D)."""
    text = run(["nm", "-D", "--defined-only", lib]).stdout
    return {line.split()[-1] for line in text.splitlines() if line.strip()}


#: The Model Exchange functions of each FMI version (FMI 2.0.5 sec. 3.2, FMI 3.0.2
#: sec. 3.2): the binaries export them beside the Co-Simulation ones.
ME_FUNCTIONS = {
    2: {"fmi2EnterEventMode", "fmi2NewDiscreteStates", "fmi2EnterContinuousTimeMode",
        "fmi2CompletedIntegratorStep", "fmi2SetTime", "fmi2SetContinuousStates",
        "fmi2GetDerivatives", "fmi2GetEventIndicators", "fmi2GetContinuousStates",
        "fmi2GetNominalsOfContinuousStates"},
    3: {"fmi3InstantiateModelExchange", "fmi3EnterContinuousTimeMode",
        "fmi3CompletedIntegratorStep", "fmi3SetTime", "fmi3SetContinuousStates",
        "fmi3GetContinuousStateDerivatives", "fmi3GetEventIndicators",
        "fmi3GetContinuousStates", "fmi3GetNominalsOfContinuousStates",
        "fmi3GetNumberOfEventIndicators", "fmi3GetNumberOfContinuousStates"}}


def declared_functions(fmi: int) -> set[str]:
    """The FMI functions the sources declare: the function-prefix macros of the
    header and of the Model Exchange glue (``#define fmi2X fmi2FullName(fmi2X)``)."""
    native_dir = ROOT / "fmu_src" / "native"
    text = "".join((native_dir / f"fmi{fmi}_{name}").read_text()
                   for name in ("api.h", "me.c"))
    return set(re.findall(rf"#define (fmi{fmi}\w+)[\s\\]+fmi{fmi}FullName\(\1\)", text))


def test_darwin_binaries_are_macho_exporting_the_fmi_functions(fmu, tmp_path):
    """Exactly the FMI functions the sources declare (Model Exchange's included),
    which the linux binary exports too."""
    if shutil.which("nm") is None:
        pytest.skip("nm (binutils) lists the linux binary's exports")
    fmi, path = fmu
    lib = tmp_path / "linux.so"
    lib.write_bytes(_binary(path, LINUX[fmi][0], ".so"))
    expected = elf_exports(lib)
    assert expected == declared_functions(fmi), expected ^ declared_functions(fmi)
    assert ME_FUNCTIONS[fmi] <= expected
    assert {f"fmi{fmi}DoStep", f"fmi{fmi}GetFloat64" if fmi == 3
            else "fmi2GetReal"} <= expected
    assert len(expected) == (44 if fmi == 2 else len(expected)) > 30
    for platform, cpu in DARWIN[fmi].items():
        got_cpu, filetype, names = macho_exports(_binary(path, platform, ".dylib"))
        assert got_cpu == cpu, platform
        assert filetype == 6, platform  # MH_DYLIB
        assert names - LINKER_SYMBOLS == expected, (platform, names ^ expected)


# ---------------------------------------------------------------------- glibc


def glibc_versions(lib: Path) -> set[tuple[int, ...]]:
    """The GLIBC_x.y versions an ELF shared object needs (readelf -V)."""
    text = run(["readelf", "-V", "-W", lib]).stdout
    return {tuple(int(x) for x in v.split("."))
            for v in re.findall(r"Name: GLIBC_([0-9.]+)", text)}


def test_linux_binaries_need_at_most_the_glibc_floor(fmu, tmp_path):
    if shutil.which("readelf") is None:
        pytest.skip("readelf (binutils) reads the ELF symbol versions")
    fmi, path = fmu
    floor = tuple(int(x) for x in native.GLIBC_FLOOR.split("."))
    assert floor <= (2, 28)  # RHEL 8
    for platform in LINUX[fmi]:
        lib = tmp_path / f"{platform}.so"
        lib.write_bytes(_binary(path, platform, ".so"))
        versions = glibc_versions(lib)
        assert versions, platform  # it links against glibc at all
        assert max(versions) <= floor, (platform, sorted(versions))


# ---------------------------------------------------------------------- running


def _instances(seed: int):
    rng = np.random.default_rng(seed)
    return [(random_instance(rng, LAW_LAYOUT[1]), random_trajectory(rng, STEPS)),
            (random_general_instance(rng, GENERAL_LAYOUT[0]),
             random_trajectory(rng, STEPS))]


def _host_run(cmd, folder: Path, instances) -> list[bytes]:
    """Run the C host command (ending in LIBRARY GUID CONFIG) on ``instances``; the
    output files' bytes."""
    proc = run(cmd)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert f"DONE {STEPS} steps, {len(instances)} instances" in proc.stdout
    return [(folder / f"out{i}.bin").read_bytes() for i in range(len(instances))]


def _setup(tmp_path, fmu_path, instances):
    from fmpy import extract, read_model_description

    md = read_model_description(str(fmu_path))
    unzip = Path(extract(str(fmu_path), str(tmp_path / "fmu")))
    cfg = tmp_path / "host.cfg"
    cfg.write_text(host_config(tmp_path, md, instances, H))
    return md, unzip, cfg


def _linux64_reference(tmp_path, unzip, md, cfg, instances) -> list[bytes]:
    exe = tmp_path / "host_x86_64"
    proc = run(["gcc", "-std=c99", "-D_POSIX_C_SOURCE=200809L", "-O2", "-o", exe,
                ROOT / "tests" / "c_host" / "native_host.c", "-ldl"])
    assert proc.returncode == 0, proc.stderr
    lib = unzip / "binaries" / "linux64" / f"{IDENT[2]}.so"
    return _host_run([exe, lib, md.guid, cfg], tmp_path, instances)


def test_aarch64_linux_under_qemu_equals_linux64_bit_for_bit(tmp_path):
    """2 instances x 2e4 steps (macro-slip on two axes, micro-slip with 8 and 64
    sliders, fs_ratio): the aarch64 binary under qemu-user gives the same bytes as
    the linux64 binary."""
    need_zig()
    qemu = shutil.which("qemu-aarch64")
    if qemu is None:
        pytest.skip("apt-get install qemu-user runs the aarch64 binary")
    if not (AARCH64_SYSROOT / "lib" / "ld-linux-aarch64.so.1").exists():
        pytest.skip("apt-get install libc6-arm64-cross: the aarch64 C library")
    path = build(tmp_path, 2)
    instances = _instances(30)
    md, unzip, cfg = _setup(tmp_path, path, instances)
    ref = _linux64_reference(tmp_path, unzip, md, cfg, instances)
    exe = tmp_path / "host_aarch64"
    proc = run([*native._zig_command(), "cc", "-target",
                f"aarch64-linux-gnu.{native.GLIBC_FLOOR}", "-std=c99",
                "-D_POSIX_C_SOURCE=200809L", "-O2", "-o", exe,
                ROOT / "tests" / "c_host" / "native_host.c", "-ldl"])
    assert proc.returncode == 0, proc.stderr
    lib = unzip / "binaries" / "aarch64-linux" / f"{IDENT[2]}.so"
    got = _host_run([qemu, "-L", AARCH64_SYSROOT, exe, lib, md.guid, cfg], tmp_path,
                    instances)
    for r, g in zip(ref, got, strict=True):
        assert len(g) == STEPS * 16 * 8
        a, b = np.frombuffer(r, "<f8"), np.frombuffer(g, "<f8")
        assert g == r, f"{np.count_nonzero(a != b)} of {a.size} values differ"
    assert np.frombuffer(ref[0], "<f8").reshape(STEPS, 16)[:, 13:].any()  # slipped


def _windows_compiler() -> tuple[str, ...] | None:
    """MinGW's gcc, else ``zig cc`` for x86_64-windows-gnu (the host .exe)."""
    mingw = shutil.which("x86_64-w64-mingw32-gcc")
    if mingw is not None:
        return (mingw,)
    zig = native._zig_command()
    return None if zig is None else (*zig, "cc", "-target", "x86_64-windows-gnu")


def test_win64_dll_under_wine_equals_linux64(tmp_path):
    """The win64 DLL in the C host built with MinGW (or zig cc), under wine: the same
    bytes as linux64 (skipped without wine or a Windows C compiler)."""
    wine = shutil.which("wine") or shutil.which("wine64") or next(
        (str(p) for p in [WINE64_DEBIAN] if p.exists()), None)
    compiler = _windows_compiler()
    if wine is None or compiler is None:
        pytest.skip("apt-get install wine64 (and gcc-mingw-w64-x86-64 or pip install "
                    "'drymount[native-cross]') runs the win64 DLL")
    path = build(tmp_path, 2)
    instances = _instances(31)
    md, unzip, cfg = _setup(tmp_path, path, instances)
    ref = _linux64_reference(tmp_path, unzip, md, cfg, instances)
    exe = tmp_path / "host.exe"
    proc = run([*compiler, "-std=c99", "-O2", "-o", exe,
                ROOT / "tests" / "c_host" / "native_host.c"])
    assert proc.returncode == 0, proc.stderr
    dll = unzip / "binaries" / "win64" / f"{IDENT[2]}.dll"
    got = _host_run([wine, exe, dll, md.guid, cfg], tmp_path, instances)
    assert got == ref
