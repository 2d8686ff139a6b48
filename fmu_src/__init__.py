"""Sources of the FrictionMount FMU. Kept light: this package also runs inside the FMU.

``mount_law`` is the law registry shared by the FMU, ``vehicle`` and ``hbm`` (each
elastic law and the friction element defined once); ``interface`` the FMU's variables,
units and capabilities in one table; ``friction_mount`` the pythonfmu slave (glue
only). Standard library only (plus pythonfmu for the slave).
"""
