"""Point files: PCD, PLY, LAS/LAZ, ``.npz`` and text in and out, and terrain tiles."""

__all__: list[str] = []
