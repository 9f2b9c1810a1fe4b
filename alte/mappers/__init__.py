"""The terrain mappers: the contract (:mod:`~alte.mappers.api`), the thesis' four, the
registry that resolves every name (:mod:`~alte.mappers.registry`), and map export.

The mappers (and numba) load on first use (``lazy_loader``, names declared in
``__init__.pyi``): the protocol, the domain and the feed are light to import.
"""

import lazy_loader as lazy

__getattr__, __dir__, __all__ = lazy.attach_stub(__name__, __file__)
