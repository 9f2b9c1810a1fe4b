"""Input/output in three folders: ROS bags (`bags`), point files (`points`), poses (`poses`).

``read_frames`` is the pipeline's entry point (bag -> frames); ``write_bag`` /
``write_frames`` write ROS 2 bags the simulator and tests read back.
"""

import lazy_loader as lazy

# Submodules load on first use; the names are those of __init__.pyi.
__getattr__, __dir__, __all__ = lazy.attach_stub(__name__, __file__)
