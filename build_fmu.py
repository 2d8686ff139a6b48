"""Build dist/FrictionMount.fmu (FMI 2.0 Co-Simulation): ``python build_fmu.py [dest]``.

A thin wrapper around :func:`fmu_build.build_fmu`; see docs/fmu.md.
"""

import sys

from fmu_build import build_fmu

if __name__ == "__main__":
    if len(sys.argv) > 2 or (len(sys.argv) == 2 and sys.argv[1].startswith("-")):
        sys.exit("usage: python build_fmu.py [dest.fmu]  "
                 "(default dist/FrictionMount.fmu)")
    print(build_fmu(*sys.argv[1:]))
