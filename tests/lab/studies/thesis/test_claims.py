"""The claims catalogue: verbatim quotes, consistent checks, lookups."""

from __future__ import annotations

import re
from dataclasses import fields

import pytest

from alte.errors import ParameterError
from alte.lab.studies.analysis.tradeoff import METRICS, OPTIONAL_COLUMNS, REQUIRED_COLUMNS
from alte.lab.studies.thesis.claims import (
    CASES,
    CLAIMS,
    Agreement,
    AllOf,
    Compare,
    Effect,
    NotMeasurable,
    Property,
    claim,
)
from alte.lab.studies.thesis.numbers import QUALITATIVE
from alte.mappers import make_mapper, registry
from alte.paths import realdata_dir

THESIS = realdata_dir().parent / "thesis" / "alte-thesis.txt"  # ../shared/thesis
_MAPPER_FIELDS = ("better", "other", "mapper")
_COLUMN_FIELDS = ("metric", "size", "fidelity", "reference", "reference_other", "column")
_PARAM_FIELDS = ("param", "x", "other_param")

#: The thesis' four by name.
BUILTIN = {cls.name: cls for cls in registry.BUILTIN}


def _parts(item):
    return item.check.parts if isinstance(item.check, AllOf) else (item.check,)


def _words(text: str) -> str:
    return " ".join(text.split())


def test_ids_are_unique_and_sections_are_chapters_5_and_6():
    ids = [c.id for c in CLAIMS]
    assert len(ids) == len(set(ids)) >= 50
    assert all(re.match(r"^5\.1, table 5\.[1-4]$|^(5\.1\.1|5\.2\.2) \(|^6$", c.section)
               for c in CLAIMS)
    sections = {c.section.split(" ")[0] for c in CLAIMS}
    assert sections == {"5.1,", "5.1.1", "5.2.2", "6"}


@pytest.mark.skipif(not THESIS.exists(), reason=f"thesis text not at {THESIS}")
def test_text_quotes_are_verbatim():
    text = _words(THESIS.read_text(encoding="utf-8"))
    quoted = [c for c in CLAIMS if "table" not in c.section]
    assert len(quoted) >= 40
    missing = [c.id for c in quoted if _words(c.quote) not in text]
    assert not missing


def test_table_quotes_match_the_transcribed_tables():
    names = {"Quadtree": "quadtree", "2D ALTE": "alte2d", "Octomap": "octomap",
             "3D ALTE": "alte3d"}
    tables = [c for c in CLAIMS if "table" in c.section]
    assert len(tables) == 14
    for item in tables:
        number = int(item.section.rsplit(".", 1)[1])
        criterion, cells = item.quote.split(": ", 1)
        key = criterion.lower().replace(" ", "_")
        found = re.findall(r"(Quadtree|2D ALTE|Octomap|3D ALTE) (\w+)", cells)
        assert len(found) == 2, item.id
        for name, label in found:
            assert QUALITATIVE[number][names[name]][key] == label, item.id


def test_checks_name_known_mappers_columns_and_parameters():
    columns = set(REQUIRED_COLUMNS) | set(OPTIONAL_COLUMNS) | set(METRICS)
    for item in CLAIMS:
        for part in _parts(item):
            if isinstance(part, NotMeasurable):
                assert len(part.reason) > 30
                continue
            if isinstance(part, Property):
                assert set(part.true) | set(part.false) <= set(BUILTIN)
                continue
            values = {f.name: getattr(part, f.name) for f in fields(part)}
            if isinstance(part, Agreement):  # its ``other`` is a metric, not a mapper
                values["reference_other"] = values.pop("other")
            if isinstance(part, Effect):  # its ``other`` is a parameter
                values["other_param"] = values.pop("other")
            assert values["case"] in CASES, item.id
            mappers = [values[k] for k in _MAPPER_FIELDS if values.get(k)]
            assert mappers and set(mappers) <= set(BUILTIN), item.id
            assert {values[k] for k in _COLUMN_FIELDS if values.get(k)} <= columns, item.id
            for key in _PARAM_FIELDS:
                if values.get(key) and values[key] not in columns:
                    assert values[key] in make_mapper(mappers[0]).params.as_dict(), (item.id,
                                                                          values[key])


def test_compare_checks_are_consistent():
    for item in CLAIMS:
        for part in _parts(item):
            if isinstance(part, Compare):
                assert part.better != part.other
                assert part.factor >= 1.0
                if part.at == "equal_fidelity":
                    assert part.metric in ("basis_functions", "memory_bytes", "elapsed_s")


def test_every_verdict_rule_is_explained_where_a_reading_was_chosen():
    ambiguous = [c for c in CLAIMS if isinstance(c.check, AllOf) and len(c.check.parts) > 1
                 and not c.id.startswith("5.2.2-2d") and not c.id.startswith("5.2.2-3d")]
    assert all(c.reading for c in ambiguous if "drivers" not in c.id)


def test_claim_lookup():
    assert claim("5.2.2-2d-size").quote == "but ALTE has twenty times fewer basis functions"
    with pytest.raises(ParameterError, match=r"no claim 'nope'; ids: t5\.1-adaptability, "
                       r"t5\.1-robustness, t5\.1-development, "):
        claim("nope")


def test_every_claim_bears_on_one_of_the_thesis_questions():
    from alte.lab.studies.thesis.claims.questions import QUESTIONS, question

    asked = {c.id: question(c) for c in CLAIMS}
    assert set(asked.values()) == set(QUESTIONS)
    assert asked["t5.3-obstacles"] == asked["6-landing-reliable"] == "landing"
    assert asked["6-3d-undecided"] == asked["t5.4-size"] == "navigation"
    assert asked["6-overall"] == "both" and asked["6-hd-inconsistent"] == "metric"
    assert asked["6-occupancy-level"] == asked["t5.2-robustness"] == "parameters"
    assert asked["t5.1-development"] == asked["t5.4-free-space"] == "design"
    measured = [c.id for c in CLAIMS if isinstance(c.check, NotMeasurable)]
    assert measured == ["t5.1-development", "t5.2-development", "t5.4-free-space",
                        "5.1.1-alte2d-superior"]  # code maturity and design properties only
