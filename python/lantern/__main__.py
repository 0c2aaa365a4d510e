"""`python -m lantern` entry point; see lantern.cli."""

import sys

from .cli import main

sys.exit(main())
