"""alte: Adaptive Learning Terrain Estimation workbench for UAV LiDAR mapping.

The package loads its parts on first use (``lazy_loader``, names declared in
``__init__.pyi``): ``alte --version`` or ``alte --help`` import no numpy, and each
command imports only what it runs.
"""

import lazy_loader as lazy

__getattr__, __dir__, _ = lazy.attach_stub(__name__, __file__)
__all__ = ["AlteError", "Frame", "Mount", "__version__", "thesis_mount"]

__version__ = "0.1.0"
