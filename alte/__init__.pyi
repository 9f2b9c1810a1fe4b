from .errors import AlteError
from .types import Frame, Mount, thesis_mount

__all__ = ["AlteError", "Frame", "Mount", "__version__", "thesis_mount"]

__version__: str
