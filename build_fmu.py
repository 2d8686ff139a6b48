"""Build the FrictionMount FMU: ``python build_fmu.py [dest] [--native [--fmi 2|3]]``.

Default: dist/FrictionMount.fmu (FMI 2.0, PythonFMU), a thin wrapper around
:func:`fmu_build.build_fmu`. ``--native``: the C build,
dist/FrictionMountNative.fmu (FMI 2.0) or with ``--fmi 3`` dist/FrictionMountNative3.fmu
(:func:`fmu_build.native.build_native_fmu`; it says on stderr which platforms it
built and why any was skipped). See docs/fmu.md, "Which FMU".
"""

import argparse
import sys

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("dest", nargs="?", default=None, help="FMU file to write")
    parser.add_argument("--native", action="store_true", help="the C build")
    parser.add_argument("--fmi", type=int, choices=(2, 3), default=None,
                        help="FMI version of the native build (default 2)")
    args = parser.parse_args()
    if args.native:
        from drymount.fmu_build.native import build_native_fmu

        build = build_native_fmu(args.dest, fmi=args.fmi or 2)
        print(build.summary(), file=sys.stderr)  # which platforms, why any skipped
        print(build.path)
    elif args.fmi not in (None, 2):
        sys.exit("--fmi 3 needs --native: the PythonFMU build is FMI 2.0 only")
    else:
        from drymount.fmu_build import build_fmu

        print(build_fmu(*([args.dest] if args.dest else [])))
