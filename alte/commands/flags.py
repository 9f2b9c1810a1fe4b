"""The command line's names for the library's settings.

The library's errors name a setting in its own terms (``AlteError.settings``:
``"read.pose_file"``, a record's ``OWNER.field``); the command line names its flags.
:func:`flag_message` puts the flags a command has in front of such an error's message,
so ``alte map`` says ``--pose-file, --pose-topic: read: pose_file and pose_topic exclude
each other`` where the library says the part after the flags.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping

from alte.errors import AlteError

__all__ = ["FLAGS", "flag_message", "flags_of"]

#: Library setting (``OWNER.field``) -> the flag that sets it, on every command that has it.
FLAGS: dict[str, str] = {
    "frame spec.frames": "--frames", "frame spec.voxel": "--voxel",
    "frame spec.max_rate": "--max-rate", "frame spec.max_offset": "--max-offset",
    "frame spec.origin": "--origin", "frame spec.poses": "--poses",
    "frame spec.pose_file": "--pose-file", "frame spec.pose_topic": "--pose-topic",
    "frame spec.mount": "--mount", "frame spec.crop": "--crop", "mount": "--mount",
    "read.pose_file": "--pose-file", "read.pose_topic": "--pose-topic",
    "odometry.method": "--odometry", "odometry.settings": "--odometry-set",
    "import.ground_class": "--ground-class", "import.ground_method": "--ground-method",
    "import.ground_settings": "--ground-set", "import.ground_file": "--ground",
    "import.region": "--region", "import.crs": "--crs", "import.cell": "--cell",
    "import.name": "--name", "output.overwrite": "--force", "output.path": "--out",
    "sensor profile.name": "--profile", "sweep.workers": "--workers",
    "sweep.scheduler": "--scheduler", "odometry study.reference": "--reference",
    "export.path": "--export", "export.timeline": "--timeline",
    "report.param": "--param", "report.only": "--only",
}


def flags_of(err: AlteError, options: Collection[str],
             flags: Mapping[str, str] = FLAGS) -> list[str]:
    """The flags (among a command's ``options``) of the settings ``err`` names."""
    named = [flags[s] for s in err.settings if s in flags]
    return [f for f in dict.fromkeys(named) if f in options]


def flag_message(err: AlteError, options: Collection[str],
                 flags: Mapping[str, str] = FLAGS) -> str:
    """``err``'s message, led by the flags of the settings it names (none: as it is)."""
    found = flags_of(err, options, flags)
    return f"{', '.join(found)}: {err}" if found else str(err)
