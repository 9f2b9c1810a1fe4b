"""Error types: one class per area, all derived from :class:`AlteError`.

Every message names the file, topic, frame or parameter at fault, so a user
can act on it without reading a traceback.
"""

from __future__ import annotations

__all__ = [
    "AlteError",
    "BagError",
    "ContractError",
    "GroundError",
    "MapperError",
    "MetricsError",
    "ParameterError",
    "PointFileError",
    "PoseError",
    "RegistrationError",
    "ReportError",
    "SimulationError",
    "TopicError",
]


class AlteError(Exception):
    """Base of every error alte raises on purpose.

    ``setting`` names the settings at fault in the library's own terms, ``OWNER.field``
    (``"read.pose_file"``): the command line turns them into its flags
    (:mod:`alte.commands.flags`); the library's message never names a flag.
    """

    def __init__(self, *args: object, setting: str | tuple[str, ...] = ()) -> None:
        super().__init__(*args)
        self.settings: tuple[str, ...] = (setting,) if isinstance(setting, str) else setting


class BagError(AlteError):
    """A bag is missing, truncated, corrupt or holds unusable messages."""


class TopicError(BagError):
    """A cloud or pose topic is absent, ambiguous or of the wrong type."""


class PoseError(AlteError):
    """A pose is unusable (zero quaternion, gap, non-monotonic stamps)."""


class PointFileError(AlteError):
    """A point file (PCD, PLY, LAS/LAZ, xyz text) is missing or malformed."""


class GroundError(AlteError):
    """No ground plane can be fitted (too few or degenerate points)."""


class RegistrationError(AlteError):
    """Frames cannot be registered into an inertial cloud."""


class ParameterError(AlteError, ValueError):
    """A parameter (mapper, notebook, CLI option) is out of range or unknown."""


class MapperError(AlteError):
    """A mapper was used wrongly (unknown name, bad input array)."""


class ContractError(MapperError):
    """A mapper class breaks the mapper contract (:mod:`alte.mappers.api`): a plugin the
    registry refuses, or a failure of :func:`alte.testing.check_mapper`."""


class MetricsError(AlteError):
    """A metric cannot be computed from the given sets."""


class SimulationError(AlteError):
    """A simulated terrain or scenario is unknown or inconsistent."""


class ReportError(AlteError):
    """The report runner failed to execute or collect a notebook."""
