"""`python -m loadtest ...` = `bearing-twin-loadtest ...`."""

import sys

from loadtest.cli import main

sys.exit(main())
