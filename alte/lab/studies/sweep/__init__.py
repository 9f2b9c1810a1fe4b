"""Parameter sweeps at scale: a YAML grid of terrains x mappers x parameters, run
serially or on Dask distributed, stored as a resumable Parquet dataset.

``load_spec(path)`` -> :class:`SweepSpec`; ``run_sweep(spec, scheduler=...)`` runs
the runs not yet stored and returns the table; ``load_results(folder)`` reads it
back. Thesis 5.2.2 found the mappers "sensitive to tuning parameters"; the sweeps
map that sensitivity over whole grids instead of six hand-picked rows.
"""

from alte.lab.studies.sweep.analysis import (
    main_effects,
    mapper_rows,
    param_columns,
    sensitivity_ranking,
    sensitivity_table,
)
from alte.lab.studies.sweep.runner import (
    SERIAL,
    MapUnordered,
    SweepResult,
    executor,
    override,
    run_one,
    run_sweep,
    variant_table,
)
from alte.lab.studies.sweep.runs import SweepRun, plan_runs, plan_variants
from alte.lab.studies.sweep.spec import (
    MapperGrid,
    SweepSettings,
    SweepSpec,
    load_spec,
    parse_spec,
    with_plugins,
)
from alte.lab.studies.sweep.store import (
    KEY_COLUMNS,
    TIMING_COLUMNS,
    finished_ids,
    load_results,
    write_row,
)
from alte.lab.studies.sweep.variants import BASE, Variant

__all__ = [
    "BASE",
    "KEY_COLUMNS",
    "SERIAL",
    "TIMING_COLUMNS",
    "MapUnordered",
    "MapperGrid",
    "SweepResult",
    "SweepRun",
    "SweepSettings",
    "SweepSpec",
    "Variant",
    "executor",
    "finished_ids",
    "load_results",
    "load_spec",
    "main_effects",
    "mapper_rows",
    "override",
    "param_columns",
    "parse_spec",
    "plan_runs",
    "plan_variants",
    "run_one",
    "run_sweep",
    "sensitivity_ranking",
    "sensitivity_table",
    "variant_table",
    "with_plugins",
    "write_row",
]
