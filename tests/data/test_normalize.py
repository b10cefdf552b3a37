"""Raw NL2TL rows to records: operators, grounding, uids, rejected rows."""

import hashlib
import re

from ara.data.normalize import (
    detokenize,
    grounded_name,
    lifted_tokens_to_text,
    normalize_navi,
    normalize_timed,
)
from ara.data.store import RAW_DIR


def navi_row(ltl, props=None, sentence="when possible pick apple and always go to house"):
    """A navi row in the raw layout, with two propositions by default."""
    props = props or {"prop_1": {"span": [2, 4], "prop": [["pick_v", "apple_n"]]},
                      "prop_2": {"span": [6, 9], "prop": [["go_to_v", "house_n"]]}}
    return {"id": 1, "sentence": sentence.split(), "ltl": [],
            "logic_sentence": "when possible ( prop_1 ) and always ( prop_2 )".split(),
            "logic_ltl": ltl.split(), "propositions": props}


def test_word_operators_and_dash_negation_become_symbols():
    """Tests the token mapping of both raw spellings."""
    assert lifted_tokens_to_text("globally ( negation prop_1 or prop_2 )".split()) == \
        "G ( ! prop_1 | prop_2 )"
    assert lifted_tokens_to_text("F ( - prop_1 ) -> prop_2".split()) == "F ( ! prop_1 ) -> prop_2"
    assert lifted_tokens_to_text(["until", "[12,65]"]) == "U [12,65]"


def test_navi_row_gives_a_lifted_and_a_grounded_record():
    """Tests one row: canonical STL, grounded names from the propositions, sorted aps."""
    records, rejected = normalize_navi([navi_row("F ( prop_1 ) & G ( prop_2 )")])
    assert rejected == []
    lifted, grounded = records
    assert (lifted.form, lifted.stl, lifted.aps) == ("lifted", "F(prop_1) & G(prop_2)",
                                                     ("prop_1", "prop_2"))
    assert lifted.nl == "when possible (prop_1) and always (prop_2)"
    assert grounded.stl == "F(pick_apple) & G(go_to_house)"
    assert grounded.aps == ("go_to_house", "pick_apple")
    assert lifted.row == grounded.row == 0


def test_malformed_rows_are_reported_not_dropped():
    """Tests that rows which do not parse, or lack a grounding, come back as rejected."""
    rows = [navi_row("F ( prop_1 prop_2 ) | F ( prop_3 )"),  # as in 26 navi rows
            navi_row("F ( prop_1 ) & F ( prop_3 )"),  # prop_3 has no grounding
            navi_row("prop_1 & prop_2")]
    records, rejected = normalize_navi(rows)
    assert [r.row for r in rejected] == [0, 1]
    assert "expected ')' or an operator, found 'prop_2'" in rejected[0].error
    assert "['prop_3'] have no grounding" in rejected[1].error
    assert {r.row for r in records} == {2}


def test_uids_are_content_hashes_unique_across_repeats():
    """Tests that identical rows get distinct, deterministic uids."""
    rows = [navi_row("prop_1 & prop_2")] * 3
    first, _ = normalize_navi(rows)
    again, _ = normalize_navi(rows)
    uids = [r.uid for r in first]
    assert len(set(uids)) == 6 and uids == [r.uid for r in again]
    assert all(re.fullmatch(r"[0-9a-f]{16}", u) for u in uids)


def test_timed_rows_keep_their_intervals():
    """Tests a timed row with word operators and an interval token."""
    row = {"logic_ltl": "globally ( prop_1 imply finally [12,65] ( prop_2 ) )".split(),
           "logic_sentence": "( prop_1 ) means ( prop_2 ) soon".split()}
    (record,), rejected = normalize_timed([row])
    assert record.stl == "G(prop_1 -> F[12,65](prop_2))" and rejected == []


def test_helpers_tidy_sentences_and_names():
    """Tests detokenize and grounded_name."""
    assert detokenize("if ( prop_1 ) , then go".split()) == "if (prop_1), then go"
    assert grounded_name(["go_to_v", "waste_basket_n"]) == "go_to_waste_basket"
    assert grounded_name(["walk_v"]) == "walk"


def test_vendored_files_match_their_provenance_note():
    """Tests that the raw files are the ones SOURCE.md lists, byte for byte."""
    note = (RAW_DIR / "SOURCE.md").read_text()
    listed = dict(re.findall(r"\| (\S+\.jsonl) \| [\d,]+ \| .*? \| ([0-9a-f]{64}) \|", note))
    assert sorted(listed) == ["lifted_stl_dev.jsonl", "lifted_stl_train.jsonl", "navi.jsonl"]
    for name, digest in listed.items():
        assert hashlib.sha256((RAW_DIR / name).read_bytes()).hexdigest() == digest
