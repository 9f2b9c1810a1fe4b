"""The realistic UAV sensor against the thesis' instantaneous scan (chapter 5's sensor table).

- :mod:`~alte.lab.studies.sensor.experiment`: each mission registered five ways and scored.
- :mod:`~alte.lab.studies.sensor.report`: its entry in the report (parameters, key table).
"""

__all__: list[str] = []
