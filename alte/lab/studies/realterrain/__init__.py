"""Real terrain decides the answer: the shared LiDAR tiles as terrains, mapped two ways.

:mod:`~alte.lab.studies.realterrain.sites` lists the shared tiles and ISPRS samples and
reads each one's terrain class off its surfaces; :mod:`~alte.lab.studies.realterrain.evidence`
flies the thesis' missions over them and maps their own points (the trade-off table's
schema); :mod:`~alte.lab.studies.realterrain.store` writes and reads the committed evidence
(``python -m alte.lab.studies.realterrain``).
"""

from alte.lab.studies.realterrain.evidence import COLUMNS, GRID, HOLD_BACK, evidence_rows, site_rows
from alte.lab.studies.realterrain.sites import (
    CLASSES,
    SITES,
    Site,
    surface_figures,
    terrain_class,
)
from alte.lab.studies.realterrain.store import (
    EVIDENCE,
    TABLE,
    load_evidence,
    summary,
    write_evidence,
)

__all__ = ["CLASSES", "COLUMNS", "EVIDENCE", "GRID", "HOLD_BACK", "SITES", "TABLE", "Site",
           "evidence_rows", "load_evidence", "site_rows", "summary", "surface_figures",
           "terrain_class", "write_evidence"]
