"""The lab: the thesis' experiments and what goes beyond them, on top of the library.

- :mod:`alte.lab.studies`: one folder per study (its experiment, figures, report entry).
- :mod:`alte.lab.plot`: the figure toolkit the studies and notebooks share.
- :mod:`alte.lab.report`: ``alte report``: runs the notebooks, writes the front page.
- :mod:`alte.lab.notebook`: what a chapter notebook calls first.

The library (:mod:`alte.io`, :mod:`alte.pipeline`, :mod:`alte.mappers`, ...) never imports
the lab (``tests/test_layers.py``); the benchmark lives outside the package, in ``bench/``.
"""

__all__: list[str] = []
