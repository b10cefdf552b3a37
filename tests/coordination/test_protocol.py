"""The help protocol: messages carry their fields, bids pick the helper."""

import pytest

from ara.coordination.planner_dp import Job
from ara.coordination.protocol import (
    REQUEST_WORDINGS,
    Helper,
    HelpRequest,
    Offer,
    ProtocolError,
    choose,
    make_offer,
    request_shots,
    request_site,
    request_text,
    run_round,
)
from ara.coordination.world import GridWorld
from ara.data.help_requests import help_props, says_template, template_help_spec

WORLD = GridWorld.paper()
CAPS = ("navigate", "report conflicts")


def request(site):
    return HelpRequest("requester", site, CAPS, request_text(site, CAPS))


def test_request_text_states_location_and_capabilities():
    text = request_text((1, 4), CAPS)
    assert text.startswith("A pallet is blocking the aisle at location (1, 4).")
    assert "drop it off at the closest free drop zone" in text
    assert "I can only navigate, report conflicts." in text
    assert request_site(text) == (1, 4)
    with pytest.raises(ProtocolError, match="names no location"):
        request_site("Please help me somewhere.")


@pytest.mark.parametrize("wording", range(len(REQUEST_WORDINGS)))
def test_every_wording_names_the_site_and_the_help_job(wording):
    """Tests that each rewording keeps what a helper needs: the site, pick, drop-off."""
    text = request_text((3, 4), CAPS, wording=wording)
    assert request_site(text) == (3, 4)
    assert "pallet" in text.lower() and "drop" in text.lower()
    assert "navigate, report conflicts" in text


def test_an_unknown_wording_is_refused():
    """Tests the range check on the wording index."""
    with pytest.raises(ProtocolError, match="wording must be 0..10"):
        request_text((3, 4), CAPS, wording=11)


def test_worked_requests_show_the_template_spec_in_the_decoding_grammar():
    """Tests that the translator's examples answer with the planner's own help spec,
    written so the decoding grammar (two arguments per &) admits it."""
    from ara.eval.translate.translator import TranslatorConfig

    for shot in request_shots():
        assert TranslatorConfig().syntax(shot.aps).accepts(shot.stl)
        assert shot.stl.startswith("((!place_")


def test_choose_takes_the_least_bid_and_the_lowest_id_on_ties():
    offers = [Offer(0, True, 5, 9), Offer(1, True, 9, 4), Offer(2, False), Offer(3, True, 1, 12)]
    assert choose(offers) == 1  # bids 14, 13, -, 13: the tie goes to the lower id
    assert choose([Offer(0, True, 1, 1), Offer(1, False)]) == 0
    assert choose([Offer(0, False)]) is None


def test_round_accepts_one_rejects_the_rest():
    helpers = [Helper(0, (0, 0), (Job((0, 2), (7, 2)),)), Helper(1, (3, 6), ()),
               Helper(2, (7, 7), (Job((7, 6), (0, 6)), Job((0, 7), (7, 7))))]
    rnd = run_round(WORLD, request((3, 4)), helpers)
    assert rnd.chosen == 1  # idle and two steps away
    assert [d.text for d in rnd.decisions] == ["reject", "accept", "reject"]
    offer = rnd.offers[1]
    assert offer.text == (f"I can help you in {offer.tau_help} minutes, but it will add "
                          f"{offer.tau_new} minutes to my overall makespan.")
    assert offer.tau_new == offer.tau_help  # an idle helper's makespan is the help job


def test_a_helper_over_its_cap_declines_with_a_reason():
    busy = Helper(0, (0, 0), (Job((7, 7), (0, 0)), Job((7, 7), (0, 0))))
    offer = make_offer(WORLD, busy, request((7, 0)), cap=30)
    assert not offer.can_help and "cap" in offer.reason and offer.text.startswith("I cannot")
    blocked = make_offer(WORLD, busy, request((1, 1)))  # an obstacle cell
    assert not blocked.can_help and "not a free cell" in blocked.reason


def test_round_trip_with_the_embedded_llm(llama_backend, finetuned):
    """The embedded model writes the request under a grammar that keeps its fields,
    and each helper plans whatever formula the shipped translator makes of it."""
    from ara.coordination.protocol import generate_request
    from ara.eval.translate.translator import Translator
    from ara.grammars import parse

    text = generate_request(llama_backend, (3, 4), CAPS)
    assert request_site(text) == (3, 4) and "I can only navigate, report conflicts." in text
    req = HelpRequest("requester", (3, 4), CAPS, text)
    helpers = [Helper(0, (0, 0), ()), Helper(1, (7, 7), (Job((7, 6), (0, 6)),))]
    rnd = run_round(WORLD, req, helpers, planner="milp", translator=Translator(finetuned))
    site, drop = (3, 4), WORLD.nearest_free_neighbour((3, 4))
    for offer, helper in zip(rnd.offers, helpers, strict=True):
        assert offer.stl and parse(offer.stl)  # logged, and in the language
        # a helper plans the formula it read: as the template's where it means the template
        if says_template(offer.stl, site, drop):
            template = make_offer(WORLD, helper, req, planner="milp")
            assert (offer.can_help, offer.tau_help, offer.tau_new) == (
                template.can_help, template.tau_help, template.tau_new)
        else:
            assert offer.can_help or offer.reason


@pytest.fixture(scope="module")
def shipped_translator(finetuned):
    """The shipped fine-tune through llama.cpp (the session's one load)."""
    from ara.eval.translate.translator import Translator

    return Translator(finetuned)


@pytest.mark.parametrize("wording", [  # the paper's words and two rewordings
    0, pytest.param(3, marks=pytest.mark.slow), pytest.param(7, marks=pytest.mark.slow)])
def test_the_shipped_translator_reads_a_reworded_request_as_the_template_spec(
        shipped_translator, wording):
    """Tests that a helper's translation of the request, however worded, is the
    pick-before-place spec the planner would write from the request's fields."""
    site = (3, 4)
    drop = GridWorld.paper().nearest_free_neighbour(site)
    result = shipped_translator.translate(request_text(site, CAPS, wording=wording),
                                          help_props(site, drop), request_shots())
    assert says_template(result.stl, site, drop)


def test_a_translation_says_the_template_or_not_whatever_its_bracketing():
    site, drop = (3, 4), (2, 4)
    pick, place = help_props(site, drop)
    assert says_template(f"(!{place} U {pick}) & (G({pick} -> F {place}) & F {place})",
                         site, drop)
    assert says_template(f"F {pick} & F {place}", site, drop) is False


def test_a_helper_given_the_bare_help_spec_still_carries_one_pallet_at_a_time():
    """Tests what a helper adds to a formula it did not write: the request can only say
    pick-before-place for the help pallet (it cannot name the helper's own jobs), and
    the helper adds that it carries one pallet at a time. Every forklift of the paper's
    trial 34 then bids exactly as with the template spec; planning the bare formula as
    it stands let the winner carry two pallets at once and bid 4 instead of 6."""
    from ara.coordination.experiment2 import CAPABILITIES
    from ara.coordination.oracle import Fleet, exact
    from ara.coordination.trials import make_trial

    trial = make_trial(34, 3034)
    before = exact(Fleet(WORLD, trial.starts, trial.jobs, cap=50))
    helpers = [Helper(k, trial.starts[k], tuple(trial.jobs[j] for j in route))
               for k, route in enumerate(before.routes)]
    req = HelpRequest("requester", trial.site, CAPABILITIES,
                      request_text(trial.site, CAPABILITIES))
    bare = template_help_spec(trial.site, trial.help_job.drop, ())
    for h in helpers:
        template = make_offer(WORLD, h, req, planner="milp")
        given = make_offer(WORLD, h, req, planner="milp", help_formula=bare)
        assert (given.can_help, given.tau_help, given.tau_new) == \
            (template.can_help, template.tau_help, template.tau_new), h.index
    bids = [make_offer(WORLD, h, req, planner="milp") for h in helpers]
    assert bids[choose(bids)].bid == 6
