"""Studies on top of the pipeline: the thesis chapters, landing, planning, real data, sweeps."""
