"""docs/design-keys.md is the schema's own reference: it must equal what the schema writes, and cover every key."""

from dataclasses import fields

from conftest import ROOT

from wgcad.design import TABLES
from wgcad.design.reference import design_keys_markdown


def test_reference_document_equals_the_schema():
    # regenerate with: python -m wgcad.design.reference > docs/design-keys.md
    assert (ROOT / "docs" / "design-keys.md").read_text() == design_keys_markdown()


def test_every_key_of_every_table_is_documented_with_a_meaning():
    text = design_keys_markdown()
    for table, cls in TABLES.items():
        assert f"## [{table}]" in text
        for f in fields(cls):
            row = [line for line in text.splitlines() if line.startswith(f"| `{f.name}` |")]
            assert row, f"{table}.{f.name} missing"
            assert f.metadata["wgcad"]["doc"], f"{table}.{f.name} has no meaning"
            # a bounded number says why its bounds are what they are
            meta = f.metadata["wgcad"]
            if meta["lo"] is not None or meta["hi"] is not None:
                assert meta["why"], f"{table}.{f.name}: bounds without a why"
