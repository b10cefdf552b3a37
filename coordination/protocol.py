"""The decentralized help protocol: request, offers, accept/reject.

A robot that cannot clear a conflict (a pallet in the aisle) broadcasts a request in
NL. Each helper translates it to STL over its *own* propositions with the same
translator and grammar as :mod:`ara.eval`, plans its jobs plus the help job, and
offers ``tau_help`` (when the requester's wait ends) and ``tau_new`` (what helping
adds to its own makespan). The requester accepts argmin(tau_help + tau_new), ties to
the lowest id, and rejects the others.

Messages are typed records that carry their NL text. Offers and decisions are written
from templates; a request from a template too, or by an LLM under a grammar whose
literal parts are the fields the helpers need (location, capabilities), so a generated
request cannot lose them.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field

from ara.coordination.events import UnsupportedSpec, Vocabulary
from ara.coordination.milp import MILPSolver
from ara.coordination.planner_dp import Job, plan_jobs
from ara.coordination.planner_milp import plan_spec
from ara.coordination.specs import job_names, jobs_spec, jobs_vocabulary
from ara.coordination.world import Cell, GridWorld, WorldError
from ara.data.help_requests import (
    carry_alone,
    help_props,
    template_help_spec,
)
from ara.errors import AraError
from ara.grammars import And, Formula, parse
from ara.grammars import to_text as stl_text

PLANNERS = ("dp", "milp")


class ProtocolError(AraError, ValueError):
    """A message that lacks a field the protocol needs."""


# -- messages -------------------------------------------------------------------------
@dataclass(frozen=True)
class HelpRequest:
    """Broadcast by a robot that needs help.

    Attributes:
        requester: Who asks.
        site: The conflict cell (where the pallet is).
        capabilities: What the requester can do itself.
        text: The NL message.
    """

    requester: str
    site: Cell
    capabilities: tuple[str, ...]
    text: str


@dataclass(frozen=True)
class Offer:
    """A helper's answer to a request.

    Attributes:
        helper: The helper's index.
        can_help: False when its spec could not be planned (see ``reason``).
        tau_help: Steps until the help job is done.
        tau_new: Steps helping adds to the helper's makespan.
        stl: The help formula the helper planned for.
        plan: The helper's new order of events (or job names).
        solve_s: Planner time.
        text: The NL message.
    """

    helper: int
    can_help: bool
    tau_help: int = 0
    tau_new: int = 0
    stl: str = ""
    plan: tuple[str, ...] = ()
    solve_s: float = 0.0
    reason: str = ""
    text: str = ""

    @property
    def bid(self) -> int:
        return self.tau_help + self.tau_new


@dataclass(frozen=True)
class Decision:
    helper: int
    accepted: bool
    text: str


#: The request, in the paper's words (App. B) and ten rewordings; each names the site
#: as "(row, col)", the pallet, the pick and the drop-off. ``{what}`` is what is blocked,
#: ``{caps}`` the requester's own capabilities.
REQUEST_WORDINGS = (
    "A pallet is blocking {what} at location ({r}, {c}). Assistance is required to move the "
    "pallet. Pick up pallet at ({r},{c}) and drop it off at the closest free drop zone. "
    "I can only {caps}.",
    "There is a pallet in {what} at ({r}, {c}). Could someone pick it up and then drop it at "
    "the nearest free drop zone? I can only {caps}.",
    "Help needed: pick up the pallet at location ({r}, {c}), then place it in the closest free "
    "drop zone. It is blocking {what}. I am only able to {caps}.",
    "I am stuck because a pallet blocks {what} at ({r}, {c}). Please first pick the pallet up, "
    "and after that drop it off at the nearest free spot. My capabilities: {caps}.",
    "Requesting assistance at location ({r}, {c}): a pallet is in {what}. Grab the pallet there "
    "and put it down at the closest free drop zone afterwards. I can only {caps}.",
    "Can a forklift help? A pallet at ({r}, {c}) is blocking {what}. It has to be picked up and "
    "then dropped off at the nearest free drop zone. I can only {caps}.",
    "Pallet blocking {what} at location ({r}, {c}). Task: pick it up, then drop it off at the "
    "closest free drop zone. I can only {caps}.",
    "{what} is blocked by a pallet at ({r}, {c}). I need someone to lift the pallet and then "
    "set it down at the nearest free drop zone. I can only {caps}.",
    "Please move the pallet at location ({r}, {c}) out of {what}: pick it up first, then drop "
    "it at the closest free drop zone. I am only able to {caps}.",
    "A pallet sits in {what} at ({r}, {c}) and I cannot pass. Collect the pallet and afterwards "
    "deliver it to the nearest free drop zone. I can only {caps}.",
    "Assistance required: there is a pallet at location ({r}, {c}) blocking {what}. Pick up the "
    "pallet and, once it is picked up, drop it off at the closest free drop zone. I can only "
    "{caps}.",
)


def request_text(site: Cell, capabilities: Sequence[str], what: str = "the aisle",
                 wording: int = 0) -> str:
    """The help request: the paper's wording (App. B) by default, or one of the
    rewordings in :data:`REQUEST_WORDINGS`, with the requester's capabilities."""
    if not 0 <= wording < len(REQUEST_WORDINGS):
        raise ProtocolError(f"wording must be 0..{len(REQUEST_WORDINGS) - 1}, got {wording}")
    text = REQUEST_WORDINGS[wording].format(what=what, r=site[0], c=site[1],
                                            caps=", ".join(capabilities))
    return text[0].upper() + text[1:]


def offer_text(tau_help: int, tau_new: int) -> str:
    return (f"I can help you in {tau_help} minutes, but it will add {tau_new} minutes to my "
            "overall makespan.")


def decline_text(reason: str) -> str:
    return f"I cannot help: {reason}."


_LOCATION = re.compile(r"\((\d+),\s*(\d+)\)")


def request_site(text: str) -> Cell:
    """The conflict cell a request names: its first ``(row, col)``.

    Raises:
        ProtocolError: The text has no ``(r, c)``.
    """
    found = _LOCATION.search(text)
    if not found:
        raise ProtocolError(f"the request names no location ('(row, col)'): {text!r}")
    return int(found.group(1)), int(found.group(2))


def generate_request(backend, site: Cell, capabilities: Sequence[str]) -> str:
    """The request written by an LLM under a grammar: it chooses the words that say
    what is blocked; every field the protocol needs is a literal of the grammar."""
    from ara.grammars import Syntax
    from ara.grammars.grammar_ir import Chars, Grammar, Lit, Opt, Ref, Rule
    from ara.grammars.stl_grammar import BuiltGrammar

    full = request_text(site, capabilities, "WHAT")
    head, tail = full.split("WHAT")
    word = Rule("word", ((Chars((("a", "z"),)),) + (Opt((Chars((("a", "z"),)),)),) * 9,))
    words = Rule("words", ((Lit("the "), Ref("word")) + (Opt((Lit(" "), Ref("word"))),) * 3,))
    grammar = Grammar((Rule("root", ((Lit(head), Ref("words"), Lit(tail)),)), words, word),
                      "root")
    built = BuiltGrammar(Syntax(aps=("p",)), grammar)
    prompt = ("Write the help request of a robot that found a pallet in its way.\n"
              f"Request: {request_text((3, 6), ('navigate',), 'the loading dock')}\n"
              f"Request: {request_text((7, 2), ('navigate', 'scan shelves'), 'the aisle')}\n"
              "Request:")
    out = backend.complete(prompt + " ", built, int(grammar.max_length()) + 1, "\n")
    text = out.text.strip()
    if request_site(text) != tuple(site):
        raise AssertionError(f"generated request lost its location: {text!r}")
    return text


# -- helpers --------------------------------------------------------------------------
@dataclass(frozen=True)
class Helper:
    """A robot that may help: where it is, its jobs (in a plan it already has).

    Attributes:
        index: Its id (ties in bids go to the lowest).
        start: Its cell.
        jobs: Its own jobs.
    """

    index: int
    start: Cell
    jobs: tuple[Job, ...]


def request_shots() -> tuple:
    """Two worked requests (other sites, the paper's wording) for the translator's
    prompt; each answer is the template's pick-before-place spec for its site."""
    from ara.eval.translate.prompt import Shot

    shots = []
    for site, drop in (((5, 2), (4, 2)), ((0, 6), (1, 6))):
        pick, place = help_props(site, drop)
        shots.append(Shot(request_text(site, ("navigate",)), (pick, place),
                          stl_text(template_help_spec(site, drop, ()))))
    return tuple(shots)


@dataclass
class HelpRound:
    """Everything one request produced, for logs and demos."""

    request: HelpRequest
    offers: list[Offer] = field(default_factory=list)
    decisions: list[Decision] = field(default_factory=list)
    chosen: int | None = None

    def to_dict(self) -> dict:
        return {"request": asdict(self.request), "offers": [asdict(o) for o in self.offers],
                "decisions": [asdict(d) for d in self.decisions], "chosen": self.chosen}


def make_offer(world: GridWorld, helper: Helper, request: HelpRequest, planner: str = "dp",
               objective: str = "paper", cap: int | None = 50, translator=None,
               solver: MILPSolver | None = None,
               help_formula: Formula | None = None) -> Offer:
    """A helper reads the request, writes its STL, plans, and bids.

    With a ``translator`` (a :class:`~ara.eval.translate.translator.Translator`) the help formula
    is its translation, repaired as ``ara translate`` repairs it (logged in the offer,
    right or wrong, and planned as it says); with ``help_formula`` it is that formula
    (over :func:`help_props`); otherwise it is the template spec. The DP planner
    handles the template spec only. The translator sees :func:`request_shots`.
    """
    if planner not in PLANNERS:
        raise ProtocolError(f"planner must be one of {PLANNERS}, got {planner!r}")
    site = request_site(request.text)
    if not world.is_free(site):
        return _decline(helper, f"{site} is not a free cell of my map")
    drop = world.nearest_free_neighbour(site)
    before = plan_jobs(world, helper.start, list(helper.jobs), "makespan")
    if not before.feasible:
        return _decline(helper, "my own jobs cannot be planned")
    if planner == "dp" and translator is None and help_formula is None:
        jobs = [*helper.jobs, Job(site, drop, name="help")]
        after = plan_jobs(world, helper.start, jobs, objective,
                          help_index=len(jobs) - 1, cap=cap)
        if not after.feasible:
            return _decline(helper, "helping would exceed my makespan cap"
                            if after.status == "over_cap" else "I cannot reach the site")
        tau_help = after.completion[-1]
        names = job_names(jobs)
        return _offer(helper, tau_help, after.makespan - before.makespan,
                      stl_text(template_help_spec(site, drop, ())),
                      tuple(names[i] for i in after.order), 0.0)
    pick, place = help_props(site, drop)
    own_vocab = jobs_vocabulary(world, list(helper.jobs))
    vocab = own_vocab.merged(Vocabulary({pick: site, place: drop}))
    others = sorted(own_vocab.events)
    template = template_help_spec(site, drop, others)
    if translator is not None:
        from ara.eval.translate.repair import translate_repaired

        # Repaired as `ara translate` repairs, so a helper reads a request as a user's
        # own translation would: the greedy answer unless it leaves part out or the
        # model doubts it.
        result = translate_repaired(translator, request.text, (pick, place),
                                    request_shots()).result
        if not result.valid:
            return _decline(helper, f"could not translate the request ({result.error})")
        help_formula = parse(result.stl)
    help_formula = template if help_formula is None else help_formula
    own = jobs_spec(list(helper.jobs), (pick, place))
    if help_formula != template:
        # A forklift carries one pallet at a time. The template says so for the help
        # pallet; a translated request says only what the requester wants (it cannot
        # name the helper's own jobs), so the helper adds its capacity itself.
        own = And((own, carry_alone(pick, place, others)))
    try:
        after = plan_spec(world, helper.start, {"own": own, "help": help_formula},
                          vocab, objective, cap, solver)
    except (UnsupportedSpec, WorldError) as err:
        return _decline(helper, str(err), stl_text(help_formula))
    if not after.feasible:
        return _decline(helper, f"no plan satisfies my spec and the help request "
                        f"({after.status})", stl_text(help_formula))
    return _offer(helper, after.help_time or 0, after.makespan - before.makespan,
                  stl_text(help_formula), after.order, after.solve_s)


def _offer(helper: Helper, tau_help: int, tau_new: int, stl: str, plan, solve_s: float) -> Offer:
    return Offer(helper.index, True, tau_help, tau_new, stl, tuple(plan), solve_s,
                 text=offer_text(tau_help, tau_new))


def _decline(helper: Helper, reason: str, stl: str = "") -> Offer:
    return Offer(helper.index, False, stl=stl, reason=reason, text=decline_text(reason))


def choose(offers: Sequence[Offer]) -> int | None:
    """argmin(tau_help + tau_new) over the helpers who can help; ties to the lowest id."""
    able = [o for o in offers if o.can_help]
    return min(able, key=lambda o: (o.bid, o.helper)).helper if able else None


def run_round(world: GridWorld, request: HelpRequest, helpers: Sequence[Helper],
              **offer_options) -> HelpRound:
    """Broadcast ``request``, collect offers, accept the best, reject the rest."""
    round_ = HelpRound(request)
    round_.offers = [make_offer(world, h, request, **offer_options) for h in helpers]
    round_.chosen = choose(round_.offers)
    round_.decisions = [Decision(o.helper, o.helper == round_.chosen,
                                 "accept" if o.helper == round_.chosen else "reject")
                        for o in round_.offers]
    return round_
