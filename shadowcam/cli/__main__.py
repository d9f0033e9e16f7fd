"""Run the command line with ``python -m shadowcam.cli``."""

import sys

from shadowcam.cli import main

sys.exit(main())
