"""``python -m alte``: the same as the ``alte`` console script."""

import sys

from alte.cli import main

sys.exit(main())
