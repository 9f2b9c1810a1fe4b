"""``python -m alte.lab.studies.realterrain``: write the committed real-terrain evidence."""

import sys

from alte.lab.studies.realterrain.store import main

sys.exit(main())
