"""``python -m alte.studies.realterrain``: write the committed real-terrain evidence."""

import sys

from alte.studies.realterrain.store import main

sys.exit(main())
