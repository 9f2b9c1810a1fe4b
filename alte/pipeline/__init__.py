"""The pipeline: an input and a map specification -> a map run.

``run(input, MapSettings(...), FrameSettings(...))`` is the one path from a bag, a terrain
folder or a point file to a map (:mod:`~alte.pipeline.run`); ``prepare`` registers
an input once for several maps (:mod:`~alte.pipeline.prepare`); the specifications
and their policies are in :mod:`~alte.pipeline.spec`.
"""

import lazy_loader as lazy

# Submodules load on first use; the names are those of __init__.pyi.
__getattr__, __dir__, __all__ = lazy.attach_stub(__name__, __file__)
