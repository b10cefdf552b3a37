"""Prepared splits on disk: manifests, versions, verification, export."""

import json

import pytest

from ara.data import DataVersionWarning, load_split, prepare, to_hf
from ara.data.store import registered_versions
from ara.errors import ConfigError, DataVersionError


@pytest.fixture(scope="module")
def prepared_root(tmp_path_factory):
    """A root with every split prepared (seed 0)."""
    from ara.data import SPLITS

    root = tmp_path_factory.mktemp("prepared")
    for split in SPLITS:
        prepare(split, 0, root)
    return root


def test_prepared_versions_are_the_registered_ones(prepared_root):
    """Tests that this release prepares exactly the versions versions.json registers.

    A failure means the normalizer, the synthetic generator, the realizer, the suite or
    the raw data changed the prepared contents: bump NORMALIZER_VERSION (or
    SYNTHETIC_VERSION) and register the new versions, never edit silently.
    """
    found = {p.name.rsplit("-", 1)[0]: p.name.rsplit("-", 1)[1]
             for p in prepared_root.iterdir() if not p.name.startswith(".")}
    assert found == registered_versions()


def test_manifest_records_what_made_the_split(prepared_root):
    """Tests the manifest fields that later runs rely on."""
    m = load_split("paper", 0, prepared_root).manifest
    assert m["split"] == "paper" and m["seed"] == 0 and m["schema_version"] == 1
    assert set(m["sources"]) == {"navi.jsonl"}
    assert m["rejected"]["count"] == 26 and len(m["rejected"]["examples"]) == 10
    assert m["files"]["test.jsonl"]["records"] == sum(m["counts"]["test"].values())


def test_preparing_again_reuses_the_same_version(prepared_root):
    """Tests idempotence: the same inputs give the same folder."""
    before = sorted(p.name for p in prepared_root.iterdir())
    again = prepare("paper", 0, prepared_root)
    assert again.folder.name in before
    assert sorted(p.name for p in prepared_root.iterdir()) == before


def test_records_load_by_part_and_form(prepared_root):
    """Tests reading records back, filtered by form."""
    split = load_split("paper", 0, prepared_root)
    lifted = split.records("test", "lifted")
    assert lifted and all(r.form == "lifted" for r in lifted)
    assert len(split.records("test")) == 2 * len(lifted)
    with pytest.raises(ConfigError, match="Did you mean 'grounded'"):
        split.records("test", "grounding")


def test_a_changed_file_is_refused(tmp_path):
    """Tests that editing a prepared file in place makes loading fail."""
    split = prepare("timed", 0, tmp_path)
    path = split.folder / "test.jsonl"
    lines = path.read_text().splitlines()
    record = json.loads(lines[0])
    record["stl"] = "F(prop_1)"
    path.write_text("\n".join([json.dumps(record, sort_keys=True)] + lines[1:]) + "\n")
    with pytest.raises(DataVersionError, match="does not match its manifest"):
        load_split("timed", root=tmp_path)


def test_a_torn_file_is_named_and_preparing_writes_it_anew(tmp_path):
    """Tests a file cut off mid-line (a full disk, a killed copy): loading names it, not
    a JSON error, and preparing, which is deterministic, writes the version anew."""
    split = prepare("timed", 0, tmp_path)
    path = split.folder / "test.jsonl"
    whole = path.read_text()
    path.write_text(whole[: len(whole) // 2])
    with pytest.raises(DataVersionError, match="ara data prepare --split timed"):
        load_split("timed", root=tmp_path)
    with pytest.warns(UserWarning, match="writing it anew"):
        again = prepare("timed", 0, tmp_path)
    assert again.folder == split.folder and path.read_text() == whole


def test_an_edited_manifest_is_refused(tmp_path):
    """Tests that hand-editing the manifest's counts breaks its version hash."""
    split = prepare("timed", 0, tmp_path)
    path = split.folder / "manifest.json"
    manifest = json.loads(path.read_text())
    manifest["seed"] = 7
    path.write_text(json.dumps(manifest))
    with pytest.raises(DataVersionError, match="version hash does not match"):
        load_split("timed", root=tmp_path)


def test_unprepared_and_unknown_splits_say_what_to_run(tmp_path):
    """Tests the messages for a split never prepared and a misspelt split name."""
    with pytest.raises(DataVersionError, match="ara data prepare --split paper --seed 3"):
        load_split("paper", 3, tmp_path, version="abc")
    # An older version of a registered split is made by the release that registered it
    with pytest.raises(DataVersionError, match="git log -p data/versions.json"):
        load_split("paper", 0, tmp_path, version="0123456789ab")
    with pytest.raises(ConfigError, match="Did you mean 'disjoint'"):
        prepare("disjoin", 0, tmp_path)


def test_unregistered_contents_warn(tmp_path, monkeypatch):
    """Tests that contents differing from the registered version raise a named warning."""
    monkeypatch.setattr("ara.data.store.registered_versions", lambda: {"timed": "000000000000"})
    with pytest.warns(DataVersionWarning, match="registers 000000000000"):
        prepare("timed", 0, tmp_path)


def test_export_to_hugging_face_datasets(prepared_root):
    """Tests the DatasetDict export keeps every record and field."""
    pytest.importorskip("datasets", reason="needs the datasets package (make setup)")
    split = load_split("paper", 0, prepared_root)
    dataset = to_hf(split, "lifted")
    assert len(dataset["test"]) == len(split.records("test", "lifted"))
    row = dataset["train"][0]
    assert set(row) == {"uid", "nl", "stl", "aps", "source", "form", "row"}
    assert isinstance(row["aps"], list)
