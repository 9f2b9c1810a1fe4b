"""Performance benchmark: our stages against real peers, as ratios.

``alte bench`` (or ``make bench``) runs the rows of :data:`bench.catalog.TITLES`
(:data:`bench.runner.ROWS` holds their functions) and writes ``reports/bench.md``,
``reports/bench.json`` and ``reports/bench_scaling.png``. Every figure is the median of
at least five repeats after a warm-up, ours interleaved with its peer in one process.
The machinery lives here (importable by :mod:`alte.commands.bench`); the documentation's
results pages hold what the runs measured. The package itself imports only the row
catalogue, so the command line can list the rows without loading their peers: the
machinery is imported from its modules (:mod:`bench.runner`, :mod:`bench.core`,
:mod:`bench.output` ...).
"""

from bench.catalog import TITLES, describe

__all__ = ["TITLES", "describe"]
