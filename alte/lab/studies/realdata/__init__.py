"""Chapter 6: the pipeline on real recordings nobody here made (``../shared/realdata``).

:mod:`~alte.lab.studies.realdata.data` locates the folder (skipping cleanly when it is absent),
loads the ISPRS airborne samples, the OctoMap scan and the VLP-16 packet bag, runs
the mappers and tabulates them; :mod:`~alte.lab.studies.realdata.ground` is the map-based
ground and its Sithole & Vosselman (2004) scores; :mod:`~alte.lab.studies.realdata.filters`
scores the ground filters on the ISPRS samples and the ALS tiles (how the default was
chosen); :mod:`~alte.lab.studies.realdata.fronts` maps a real sequence with reference poses
over a grid of settings (the trade-off fronts on real data);
:mod:`~alte.lab.studies.realdata.figures`
draws them.
"""

from alte.lab.studies.realdata.data import (
    BASELINE,
    ISPRS_FOLDER,
    GroundRun,
    IsprsSample,
    RealData,
    dataset_summary,
    default_dir,
    ground_runs,
    ground_table,
    isprs_sample,
    isprs_samples,
    locate,
    map_runs,
    map_table,
    results,
    scan_dataset,
    vlp16_dataset,
    write_csv,
)
from alte.lab.studies.realdata.filters import (
    ALS_FOLDER,
    CANDIDATES,
    PUBLISHED,
    LabelledCloud,
    als_tile,
    als_tiles,
    choose,
    filter_table,
    labelled_clouds,
    mean_table,
    reference_gaps,
)
from alte.lab.studies.realdata.fronts import (
    FRONT_COLUMNS,
    FRONT_GRID,
    SEQUENCE,
    RealSequence,
    front_table,
    reference_metrics,
    sequence_data,
)
from alte.lab.studies.realdata.ground import (
    classify_ground,
    ground_errors,
    map_heights,
    opened_surface,
    reference_labels,
)

__all__ = [
    "ALS_FOLDER",
    "BASELINE",
    "CANDIDATES",
    "FRONT_COLUMNS",
    "FRONT_GRID",
    "ISPRS_FOLDER",
    "PUBLISHED",
    "SEQUENCE",
    "GroundRun",
    "IsprsSample",
    "LabelledCloud",
    "RealData",
    "RealSequence",
    "als_tile",
    "als_tiles",
    "choose",
    "classify_ground",
    "dataset_summary",
    "default_dir",
    "filter_table",
    "front_table",
    "ground_errors",
    "ground_runs",
    "ground_table",
    "isprs_sample",
    "isprs_samples",
    "labelled_clouds",
    "locate",
    "map_heights",
    "map_runs",
    "map_table",
    "mean_table",
    "opened_surface",
    "reference_gaps",
    "reference_labels",
    "reference_metrics",
    "results",
    "scan_dataset",
    "sequence_data",
    "vlp16_dataset",
    "write_csv",
]
