"""What real returns do that the ray caster does not: dropouts and mixed pixels.

Both are options of the sensor profile (:mod:`alte.sim.profile`, where the models are
stated); both work on whole batches of scans (K scans x M rays) at once.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from alte.sim.profile import REFLECTIVITY, SensorProfile
from alte.sim.scene import CLASSES
from alte.sim.sensor import Hits

__all__ = ["BEAM_DIVERGENCE_MRAD", "lost_returns", "mixed_distance"]

#: VLP-16 beam divergence (data sheet), milliradians: the footprint of one return.
BEAM_DIVERGENCE_MRAD = 3.0
_REFLECTIVITY = np.array([REFLECTIVITY[c] for c in CLASSES])
_REFERENCE = 0.1  # reflectivity of the target that defines ``dropout_range``
_STEEPNESS = 4.0


def lost_returns(hits: Hits, class_ids: NDArray[np.uint8], profile: SensorProfile,
                 rngs: list[np.random.Generator]) -> NDArray[np.bool_]:
    """Mask (K, M) of hits whose echo is too weak to be detected (one draw per ray).

    ``class_ids`` holds the object class of every triangle; each scan draws from its
    own generator, so a scan's dropouts do not depend on the batch it was cast in.
    """
    k, m = hits.distance.shape
    draws = np.stack([g.random(m) for g in rngs]) if k else np.zeros((0, m))
    hit = hits.triangle >= 0
    refl = np.where(hit, _REFLECTIVITY[class_ids[np.maximum(hits.triangle, 0)]], 1.0)
    dist = np.where(hit, hits.distance, 1.0)
    power = refl * np.maximum(hits.cos_incidence, 1e-9) / np.maximum(dist, 1e-3) ** 2
    half = _REFERENCE / profile.dropout_range**2
    detect = 1.0 / (1.0 + (half / power) ** _STEEPNESS)
    lost: NDArray[np.bool_] = hit & (draws > detect)
    return lost


def mixed_distance(centre: Hits, left: Hits, right: Hits, profile: SensorProfile) -> Hits:
    """Distances of beams whose footprint (three sub-rays) spans surfaces within
    ``mix_distance``: their mean (a point between the surfaces); else the centre's."""
    stack = np.stack([centre.distance, left.distance, right.distance])
    finite = np.isfinite(stack).all(axis=0)
    safe = np.where(finite, stack, 0.0)
    spread = np.where(finite, safe.max(axis=0) - safe.min(axis=0), np.inf)
    mix = finite & (spread > 0) & (spread <= profile.mix_distance)
    distance = np.where(mix, safe.mean(axis=0), centre.distance)
    return Hits(distance, centre.cos_incidence, centre.triangle)
