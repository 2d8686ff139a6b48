"""``python -m drymount.studies NAME --out DIR [--quick]``."""

import sys

from drymount.studies.cli import main, parser

sys.exit(main(parser().parse_args()))
