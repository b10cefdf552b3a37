"""Help requests in the training mixture: the template's spec, never a measured wording."""

from ara.coordination.protocol import REQUEST_WORDINGS, request_site, request_text
from ara.data.help_requests import help_request_records
from ara.grammars import parse


def test_each_request_answers_with_the_template_spec_of_its_own_site():
    """The pick proposition is named after the cell the text names, as a helper reads
    it (``request_site``), and the formula is the template's three conjuncts."""
    records = help_request_records(50, seed=0)
    assert len({r.nl for r in records}) == 50
    for r in records:
        row, col = request_site(r.nl)
        pick, place = r.aps
        assert pick == f"pick_r{row}c{col}" and place.startswith("place_r")
        assert parse(r.stl) == parse(
            f"((!{place} U {pick}) & G({pick} -> F({place}))) & F({place})")


def test_no_training_request_is_a_wording_the_bench_measures():
    """The coordination bench's wordings (the paper's among them) stay unseen."""
    records = help_request_records(400, seed=0)
    measured = {request_text(request_site(r.nl), caps, what, wording=w)
                for r in records[:40] for w in range(len(REQUEST_WORDINGS))
                for caps in (("navigate",), ("navigate", "turn"))
                for what in ("the aisle", "my path", "the corridor")}
    assert not measured & {r.nl for r in records}
    # Nor does any training request contain a measured wording's task sentence.
    tasks = {w.split(". ")[1] for w in measured if w.count(". ") >= 2}
    assert not [r.nl for r in records if any(t in r.nl for t in tasks)]


def test_requests_are_reproducible_from_the_seed():
    assert help_request_records(20, 3) == help_request_records(20, 3)
    assert help_request_records(20, 3) != help_request_records(20, 4)
