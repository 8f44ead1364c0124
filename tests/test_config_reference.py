"""The config reference and the JSON Schemas are generated from the models and kept current;
every config under configs/ names its schema and validates against it."""
import json
import os
from pathlib import Path

import pytest
import yaml

from fkopt.run import config_reference as ref
ROOT = Path(__file__).resolve().parent.parent


def test_committed_reference_and_schemas_are_current():
    stale = [str(p.relative_to(ROOT)) for p, text in ref.generated(ROOT).items()
             if not p.exists() or p.read_text(encoding="utf-8") != text]
    assert not stale, f"regenerate with: python -m fkopt.run.config_reference ({stale})"


@pytest.mark.parametrize("kind", ref.kinds())
def test_every_field_of_every_model_is_documented(kind):
    missing = [f"{m.__name__}.{f}" for m in ref.models_of(kind) for f in m.model_fields
               if ref.field_doc(m.__name__, f) is None]
    assert not missing, f"add these to fkopt.run.config_reference.FIELDS: {missing}"


def test_no_documentation_for_fields_that_do_not_exist():
    fields = {(m.__name__, f) for kind in ref.kinds() for m in ref.models_of(kind) for f in m.model_fields}
    stale = [f"{m}.{f}" for m, doc in ref.FIELDS.items() for f in doc if (m, f) not in fields]
    assert not stale


@pytest.mark.parametrize("kind", ref.kinds())
def test_every_example_is_valid_for_its_field(kind):
    """Each documented example validates against the field's own schema (so examples do not rot)."""
    jsonschema = pytest.importorskip("jsonschema", reason="jsonschema is in the [test] extra")
    schema = ref.json_schema(kind)
    parts = [schema] + list(schema.get("$defs", {}).values())
    checked = 0
    for part in parts:
        for name, prop in part.get("properties", {}).items():
            for example in prop.get("examples", []):
                sub = {**prop, "$defs": schema.get("$defs", {})}
                jsonschema.validate(example, sub)
                checked += 1
    assert checked >= 10


def _config_files():
    """Every config file (a paper's claims.yaml is the claims engine's data, not a config)."""
    return sorted(p for p in (ROOT / "configs").rglob("*.yaml") if p.name != "claims.yaml")


@pytest.mark.parametrize("path", _config_files(), ids=lambda p: str(p.relative_to(ROOT / "configs")))
def test_configs_name_their_schema_and_validate_against_it(path):
    jsonschema = pytest.importorskip("jsonschema", reason="jsonschema is in the [test] extra")
    first = path.read_text(encoding="utf-8").splitlines()[0]
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    kind = data.get("kind", "experiment")
    expected = os.path.relpath(ROOT / "docs" / "schema" / f"{kind}.json", path.parent)
    assert first == f"# yaml-language-server: $schema={expected}"
    schema = json.loads((ROOT / "docs" / "schema" / f"{kind}.json").read_text(encoding="utf-8"))
    jsonschema.validate(data, schema)


def test_schema_refuses_what_the_loader_refuses():
    jsonschema = pytest.importorskip("jsonschema", reason="jsonschema is in the [test] extra")
    schema = ref.json_schema("experiment")
    good = {"name": "x", "mechanism": {"name": "3-rps"}, "cases": [{"pose": {"alpha": 0, "beta": 0, "z": 600}}],
            "algorithms": [{"name": "gabc"}]}
    jsonschema.validate(good, schema)
    for bad in ({**good, "populaton": 10}, {**good, "runs": 0}, {**good, "check": "nightly"}):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(bad, schema)


def test_reference_lists_defaults_limits_and_units():
    text = ref.markdown()
    row = next(line for line in text.splitlines() if line.startswith("| `population` | integer | `10`"))
    assert "≤ 100,000" in row and "agents" in row and "population: 10" in row
    assert "| `check` | ci \\| full |" in text
    for kind in ref.kinds():
        assert f"## {kind} files" in text
