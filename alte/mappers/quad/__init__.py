"""The 2D engine shared by Quadtree and 2D-ALTE: the square domain's per-level cells and
Morton keys (:mod:`~alte.mappers.quad.quadgrid`), their sufficient statistics
(:mod:`~alte.mappers.quad.levelstats`, numba kernels in
:mod:`~alte.mappers.quad.cellstats` and :mod:`~alte.mappers.quad.treebuild`) and the
common map machinery, plane heights included (:mod:`~alte.mappers.quad.quadmap`)."""
