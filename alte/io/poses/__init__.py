"""Vehicle poses: pose tracks interpolated at scan stamps, TUM trajectory files."""

__all__: list[str] = []
