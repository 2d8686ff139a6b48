"""Sources of the FrictionMount FMU. Kept light: this package also runs inside the FMU.

``mount_law`` is the force law shared by the FMU, ``vehicle`` and ``hbm``;
``friction_mount`` is the pythonfmu slave (glue only).
"""
