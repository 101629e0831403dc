"""Allow ``python -m ptoverify``."""

import sys

from ptoverify.cli import main

sys.exit(main())
