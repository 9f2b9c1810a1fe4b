"""The terrain specs: a parameter record whose built-in values (and hashes) never drift."""

from __future__ import annotations

import hashlib
import json
from dataclasses import replace

import pytest

from alte.errors import ParameterError
from alte.sim import TERRAINS, get_terrain

#: The first 16 hex digits of the SHA-256 of each built-in terrain's ``spec.to_dict()``:
#: it goes into the simulation cache key (``spec_hash``), so a change here would invalidate
#: every user's simulated data.
SPEC_DIGESTS = {
    "exp_lan_1": "2cbb44803c74c194", "exp_lan_2": "39a8aee116b586b1",
    "exp_nav_1": "5700f3a5446d8932", "exp_nav_2": "edb184d1215dffd0",
    "sim_lan_1": "890b38df6833d192", "sim_lan_2": "bc4934ae00688603",
    "sim_nav_1": "4446289294a065a5", "sim_nav_2": "a33e32f35250630f",
}


def test_built_in_specs_hash_as_they_always_did() -> None:
    digests = {name: hashlib.sha256(json.dumps(build().spec.to_dict(), sort_keys=True)
                                    .encode()).hexdigest()[:16]
               for name, build in TERRAINS.items()}
    assert digests == SPEC_DIGESTS


@pytest.mark.parametrize(("change", "message"), [
    ({"frames": 0}, r"terrain: frames=0 out of range \(frames >= 1\)"),
    ({"registration_voxel": -1}, r"terrain: registration_voxel=-1.0 out of range"),
    ({"crop_box": (0, 0, 0, 1, 1)}, r"terrain: crop_box=\[0.0, 0.0, 0.0, 1.0, 1.0\] out of"),
    ({"crop_box": (0, 0, 2, 1, 1, 1)}, r"crop_box=.* \(xmin,ymin,zmin,xmax,ymax,zmax"),
    ({"landing_zone": (0, 0, float("nan"))}, r"terrain: landing_zone\[2\]=nan must be finite"),
    ({"frames": "many"}, r"terrain: frames='many' is not a valid int"),
])
def test_a_bad_spec_names_its_field(change: dict[str, object], message: str) -> None:
    spec = get_terrain("exp_nav_1").spec
    with pytest.raises(ParameterError, match=message):
        replace(spec, **change)


def test_spec_values_are_coerced_from_text() -> None:
    spec = get_terrain("exp_nav_1").spec
    assert spec.replace(frames="12", registration_voxel="0.05").frames == 12
