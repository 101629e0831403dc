"""``python -m ptoverify.cli``: the command line."""

import sys

from ptoverify.cli import main

sys.exit(main())
