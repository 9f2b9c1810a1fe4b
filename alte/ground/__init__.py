"""Ground and obstacles: the ground filters of the field (SMRF, CSF), the thesis' MSAC
ground plane, and Euclidean obstacle clusters (thesis 3.13) measured from either.

The modules (pandas, open3d for the MSAC plane) load on first use (``lazy_loader``, names
declared in ``__init__.pyi``): the settings records are light to import.
"""

import lazy_loader as lazy

__getattr__, __dir__, __all__ = lazy.attach_stub(__name__, __file__)
