"""Grounded propositions for synthetic sentences: a name a formula uses
(``go_to_kitchen``) and the words a person would say for it ("head to the kitchen").

Actions read as imperatives ("do not pick up the red box"); conditions as clauses
("the door is open"); an action that triggers a response reads as an event ("whenever
you pick up the red box"). Every name is a valid proposition of the surface syntax.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from functools import cache

PLACES = (
    ("kitchen", "kitchen"), ("hallway", "hallway"), ("office", "office"), ("lab", "lab"),
    ("garage", "garage"), ("lobby", "lobby"), ("elevator", "elevator"), ("exit", "exit"),
    ("bedroom", "bedroom"), ("living_room", "living room"), ("storage_room", "storage room"),
    ("charging_station", "charging station"), ("loading_bay", "loading bay"),
    ("workshop", "workshop"), ("parking_lot", "parking lot"), ("front_door", "front door"),
    ("warehouse", "warehouse"), ("reception", "reception"), ("corridor", "corridor"),
)
NUMBERED_PLACES = (("dock", "dock"), ("zone", "zone"), ("shelf", "shelf"),
                   ("station", "station"), ("room", "room"), ("gate", "gate"))
OBJECTS = (
    ("red_box", "red box"), ("blue_cup", "blue cup"), ("green_block", "green block"),
    ("package", "package"), ("tool", "tool"), ("bottle", "bottle"), ("book", "book"),
    ("parcel", "parcel"), ("medicine", "medicine"), ("sample", "sample"),
    ("yellow_ball", "yellow ball"), ("laptop", "laptop"), ("keys", "keys"), ("mug", "mug"),
)
NUMBERED_OBJECTS = (("pallet", "pallet"), ("crate", "crate"), ("bin", "bin"))
#: Things a robot switches, opens or cleans; their verbs often sound negative ("turn off
#: the fan", "close the valve") and name a proposition all the same, never its negation.
DEVICES = (
    ("fan", "fan"), ("valve", "valve"), ("window", "window"), ("oven", "oven"),
    ("heater", "heater"), ("pump", "pump"), ("tap", "tap"), ("drawer", "drawer"),
    ("lid", "lid"), ("hatch", "hatch"), ("printer", "printer"), ("lamp", "lamp"),
    ("vacuum", "vacuum"), ("cabinet", "cabinet"), ("microwave", "microwave"),
    ("projector", "projector"), ("washing_machine", "washing machine"),
)
NUMBERED_DEVICES = (("machine", "machine"), ("locker", "locker"), ("terminal", "terminal"))

PLACE_VERBS = (
    ("go_to", ("go to the {x}", "go to {x}", "head to the {x}", "move to the {x}",
               "navigate to the {x}", "drive to the {x}")),
    ("visit", ("visit the {x}", "stop by the {x}", "visit {x}")),
    ("reach", ("reach the {x}", "get to the {x}", "arrive at the {x}")),
    ("enter", ("enter the {x}", "go into the {x}")),
    ("leave", ("leave the {x}", "exit the {x}")),
    ("at", ("be at the {x}", "be in the {x}", "stay at the {x}")),
)
OBJECT_VERBS = (
    ("pick", ("pick up the {x}", "pick the {x}", "grab the {x}", "collect the {x}")),
    ("place", ("place the {x}", "put down the {x}", "drop off the {x}")),
    ("deliver", ("deliver the {x}", "bring the {x}")),
    ("hold", ("hold the {x}", "carry the {x}")),
    ("inspect", ("inspect the {x}", "check the {x}")),
)
#: Less common things done to objects, drawn less often than :data:`OBJECT_VERBS`.
MORE_OBJECT_VERBS = (
    ("load", ("load the {x}",)), ("unload", ("unload the {x}",)),
    ("scan", ("scan the {x}",)), ("lift", ("lift the {x}", "raise the {x}")),
    ("drop", ("drop the {x}", "let go of the {x}")), ("push", ("push the {x}",)),
    ("sort", ("sort the {x}",)), ("weigh", ("weigh the {x}",)),
)
#: One-off jobs of many trades, each on things it is done to ("photograph the bridge",
#: "water the seedlings"): achievements, as `F` asks for them. Before 4.0 the verbs were
#: a robot's few, and the shipped file read an imperative with a verb it had never seen
#: ("photograph the valves on tank 2") as a job done again and again (`G(F(.))`).
TASK_VERBS = (
    ("photograph", ("photograph the {x}", "take a picture of the {x}"),
     ("bridge", "fence", "roof", "crack", "meter", "pipes", "panels")),
    ("wash", ("wash the {x}", "rinse the {x}"), ("windows", "trays", "panels", "floor", "van")),
    ("water", ("water the {x}",), ("plants", "seedlings", "lawn", "flower_beds")),
    ("paint", ("paint the {x}", "repaint the {x}"), ("fence", "wall", "railing", "bench")),
    ("measure", ("measure the {x}", "take a reading of the {x}"),
     ("pressure", "temperature", "soil", "water_level")),
    ("label", ("label the {x}", "tag the {x}"), ("boxes", "samples", "bins", "crates")),
    ("test", ("test the {x}", "run a test on the {x}"), ("alarm", "sensor", "battery", "pump")),
    ("refill", ("refill the {x}", "top up the {x}"), ("tank", "feeder", "printer", "dispenser")),
    ("restock", ("restock the {x}",), ("shelves", "fridge", "supply_cart", "minibar")),
    ("spray", ("spray the {x}",), ("crops", "weeds", "orchard", "hedges")),
    ("count", ("count the {x}", "take stock of the {x}"), ("boxes", "pallets", "tools", "chairs")),
    ("sterilize", ("sterilize the {x}", "disinfect the {x}"), ("instruments", "trays", "cart")),
    ("fold", ("fold the {x}",), ("towels", "laundry", "sheets")),
    ("tighten", ("tighten the {x}",), ("bolts", "valve", "straps")),
    ("harvest", ("harvest the {x}",), ("tomatoes", "apples", "lettuce")),
    ("feed", ("feed the {x}",), ("animals", "fish", "hens")),
)
#: One-off jobs done to a place ("vacuum the hallway", "map the warehouse").
PLACE_TASK_VERBS = (
    # not vacuum_: a kept state is called vacuum_on
    ("vacuum_clean", ("vacuum the {x}",)), ("mop", ("mop the {x}", "mop the floor of the {x}")),
    ("sweep", ("sweep the {x}",)), ("map", ("map the {x}", "make a map of the {x}")),
    ("survey", ("survey the {x}",)), ("disinfect", ("disinfect the {x}",)),
)
DEVICE_VERBS = (
    ("turn_on", ("turn on the {x}", "switch on the {x}", "start the {x}")),
    ("turn_off", ("turn off the {x}", "switch off the {x}", "shut down the {x}")),
    ("open", ("open the {x}",)), ("close", ("close the {x}", "shut the {x}")),
    ("clean", ("clean the {x}", "wipe down the {x}")),
    ("lock", ("lock the {x}",)), ("unlock", ("unlock the {x}",)),
    ("empty", ("empty the {x}",)), ("repair", ("repair the {x}", "fix the {x}")),
)
STANDALONE_ACTIONS = (
    ("charge", ("charge", "recharge the battery")), ("wait", ("wait", "stay still")),
    ("beep", ("beep", "sound the horn")), ("report", ("report", "send a report")),
    ("stop", ("stop", "halt", "come to a stop")),
    ("dock", ("dock", "return to base")), ("shut_down", ("shut down", "power off")),
    ("reverse", ("reverse", "back up")), ("honk", ("honk",)),
)
#: Achievements said as something that happens, for the trigger of a response
#: ("whenever you pick up the red box, ..."): ``G(pick_red_box -> F(...))``.
EVENTS = {
    "go_to": ("you go to the {x}", "you get to the {x}"),
    "visit": ("you visit the {x}", "you stop by the {x}"),
    "reach": ("you reach the {x}", "the {x} is reached", "you arrive at the {x}"),
    "enter": ("you enter the {x}", "you go into the {x}"),
    "leave": ("you leave the {x}", "you exit the {x}"),
    "pick": ("you pick up the {x}", "the {x} is picked up", "you grab the {x}"),
    "place": ("you put down the {x}", "the {x} is placed", "you drop off the {x}"),
    "deliver": ("you deliver the {x}", "the {x} is delivered"),
    "inspect": ("you inspect the {x}", "the {x} is inspected", "you check the {x}"),
    "charge": ("you charge", "the battery is recharged"),
    "beep": ("you beep", "the horn sounds"),
    "report": ("you report", "a report is sent"),
    "turn_on": ("you turn on the {x}", "the {x} is switched on"),
    "turn_off": ("you turn off the {x}", "the {x} is switched off"),
    "open": ("you open the {x}", "the {x} is opened"),
    "close": ("you close the {x}", "the {x} is shut"),
    "clean": ("you clean the {x}", "the {x} is cleaned"),
    "load": ("you load the {x}", "the {x} is loaded"),
    "unload": ("you unload the {x}", "the {x} is unloaded"),
    "scan": ("you scan the {x}", "the {x} is scanned"),
    "drop": ("you drop the {x}", "the {x} is dropped"),
}
CONDITIONS = (
    ("door_open", ("the door is open",)), ("battery_low", ("the battery is low",
                                                          "the battery runs low")),
    ("obstacle_detected", ("an obstacle is detected", "an obstacle is seen")),
    ("person_nearby", ("a person is nearby", "someone is close by")),
    ("alarm_on", ("the alarm is on", "the alarm goes off")),
    ("light_red", ("the light is red",)), ("light_green", ("the light is green",)),
    ("gripper_closed", ("the gripper is closed",)), ("task_done", ("the task is done",)),
    ("path_blocked", ("the path is blocked",)), ("floor_wet", ("the floor is wet",)),
    ("human_request", ("a human asks for help", "a person requests help")),
    # Conditions whose words sound negative name a proposition, not its negation
    ("lights_off", ("the lights are off",)), ("tank_empty", ("the tank is empty",)),
    ("signal_lost", ("the signal is lost", "the connection drops")),
    ("motor_stopped", ("the motor has stopped", "the motor is stopped")),
    ("power_low", ("power is low", "the power runs low")),
    ("temperature_high", ("the temperature is high", "it is too hot")),
    ("window_closed", ("the window is closed",)), ("area_clear", ("the area is clear",)),
    ("queue_empty", ("the queue is empty", "no orders are waiting")),
    ("sensor_offline", ("the sensor is offline", "the sensor stops working")),
    ("arm_idle", ("the arm is idle",)), ("gate_down", ("the gate is down",)),
    ("snowing", ("it is snowing",)), ("night", ("it is night",)),
)
#: Conditions about a place or an object: where the robot is, what it holds.
PLACE_STATES = (("in", ("the robot is in the {x}", "you are in the {x}")),
                ("person_in", ("a person is in the {x}", "someone is in the {x}")))
OBJECT_STATES = (("holding", ("the robot is holding the {x}", "the {x} is in the gripper")),
                 ("seen", ("the {x} is visible", "the robot sees the {x}")))
#: States a robot keeps things in ("keep the valve closed", ``valve_closed``): said as a
#: lasting action where ``G`` keeps them, as a clause ("the valve is closed") where they
#: are a condition. People say "keep X open" far more often than "X is open at all
#: times", and before 3.9 "keep" meant only "keep returning" (``G(F(.))``) in training.
SWITCHED = ("fan", "heater", "pump", "lamp", "printer", "projector", "oven", "vacuum",
            "microwave", "washing_machine", "lights", "engine", "camera", "conveyor")
OPENED = ("valve", "window", "drawer", "lid", "hatch", "cabinet", "tap", "door", "gate",
          "vents", "gripper")
LOCKED = ("cabinet", "door", "hatch", "locker", "gate")
KEPT_THINGS = (
    ("area_clear", "the area", "clear"), ("path_clear", "the path", "clear"),
    ("floor_dry", "the floor", "dry"), ("arm_still", "the arm", "still"),
    ("speed_low", "the speed", "low"), ("volume_low", "the volume", "low"),
    ("arm_raised", "the arm", "raised"), ("lights_dimmed", "the lights", "dimmed"),
    ("tank_full", "the tank", "full"), ("battery_charged", "the battery", "charged"),
    ("aisle_clear", "the aisle", "clear"), ("exit_clear", "the exit", "clear"),
    ("brakes_on", "the brakes", "on"), ("table_clean", "the table", "clean"),
)
KEPT_PHRASES = ("keep {x} {st}", "leave {x} {st}", "make sure {x} {stays} {st}",
                "{x} must stay {st}")
#: Words for a place's negation: "stay out of the kitchen" is ``!in_kitchen``.
NEGATED = {"in": ("stay out of the {x}", "keep out of the {x}", "stay away from the {x}"),
           "at": ("stay away from the {x}", "keep away from the {x}")}


@dataclass(frozen=True)
class Proposition:
    """A grounded proposition and how it may be said."""

    name: str
    phrases: tuple[str, ...]
    action: bool
    #: An action that is a state while it lasts ("hold the box", "stay at the dock",
    #: "wait"): after "whenever c" it asks for that state then, not at some later point.
    lasting: bool = False
    #: How its negation may be said ("stay out of the kitchen"), if there are words for it.
    negated: tuple[str, ...] = ()
    #: The place it is about ("the kitchen"), for being somewhere ("in", "at"): then
    #: F(G(.)) may be said "go to the kitchen and stay there".
    place: str | None = None


#: Verbs of lasting actions (see :attr:`Proposition.lasting`).
LASTING_VERBS = frozenset({"at", "hold", "wait", "stop"})
#: Verbs of being somewhere (see :attr:`Proposition.place`).
BEING_AT = frozenset({"at", "in"})


def draw_propositions(rng: random.Random, k: int, conditions: frozenset[int] = frozenset(),
                      states: frozenset[int] = frozenset(),
                      triggers: frozenset[int] = frozenset(),
                      places: frozenset[int] = frozenset(),
                      kept: frozenset[int] = frozenset()) -> list[Proposition]:
    """``k`` propositions with distinct names, mixing actions and conditions; the ones
    at the indices in ``conditions`` are conditions, those in ``states`` a condition or
    a lasting action, those in ``triggers`` a condition or an achievement said as an
    event, half and half; those in ``places`` (and none of the others) are being
    somewhere half the time, those in ``kept`` (which may also be in ``states``) a kept
    state ("keep the valve closed") half the time."""
    found: dict[str, Proposition] = {}
    while len(found) < k:
        i = len(found)
        if i in conditions:
            prop = _draw_condition(rng)
        elif i in triggers:
            prop = _draw_condition(rng) if rng.random() < 0.5 else _draw_event(rng)
        elif i in kept and rng.random() < 0.5:
            prop = _draw_kept(rng, as_clause=False)
        elif i in states:
            prop = _draw_condition(rng) if rng.random() < 0.5 else _draw_lasting(rng)
        elif i in places and rng.random() < 0.5:
            prop = _draw_being_at(rng)
        else:
            prop = _draw_one(rng)
        found.setdefault(prop.name, prop)
    return list(found.values())


def _draw_lasting(rng: random.Random) -> Proposition:
    kind = rng.random()
    if kind < 0.45:
        phrases = dict(PLACE_VERBS)["at"]
        name, words = _thing(rng, PLACES, NUMBERED_PLACES)
        return _about("at", phrases, name, words, action=True)
    if kind < 0.85:
        phrases = dict(OBJECT_VERBS)["hold"]
        name, words = _thing(rng, OBJECTS, NUMBERED_OBJECTS)
        return _about("hold", phrases, name, words, action=True)
    verb = "wait" if kind < 0.93 else "stop"
    return Proposition(verb, dict(STANDALONE_ACTIONS)[verb], action=True, lasting=True)


@cache
def kept_states() -> tuple[tuple[str, str, str], ...]:
    """Every (name, subject, state) :data:`KEPT_PHRASES` may say."""
    switched = tuple((f"{x}_{st}", x, st) for x in SWITCHED for st in ("on", "off"))
    opened = tuple((f"{x}_{st}", x, st) for x in OPENED for st in ("open", "closed"))
    locked = tuple((f"{x}_locked", x, "locked") for x in LOCKED)
    things = tuple((name, f"the {x.replace('_', ' ')}", st)
                   for name, x, st in switched + opened + locked)
    return things + KEPT_THINGS


def _draw_kept(rng: random.Random, as_clause: bool) -> Proposition:
    """A state kept ("keep the valve closed"), or said as a clause ("the valve is
    closed") where it is a condition."""
    name, subject, state = rng.choice(kept_states())
    plural = subject.endswith("s") and not subject.endswith("ss")
    if as_clause:
        return Proposition(name, (f"{subject} {'are' if plural else 'is'} {state}",),
                           action=False)
    phrases = tuple(dict.fromkeys(p.format(x=subject, st=state,
                                           stays="stay" if plural else "stays")
                                  for p in KEPT_PHRASES))
    return Proposition(name, phrases, action=True, lasting=True)


def _draw_being_at(rng: random.Random) -> Proposition:
    """Being at a place: a lasting action ("stay at the dock") or a condition ("the
    robot is in the kitchen")."""
    name, words = _thing(rng, PLACES, NUMBERED_PLACES)
    if rng.random() < 0.5:
        return _about("at", dict(PLACE_VERBS)["at"], name, words, action=True)
    return _about("in", dict(PLACE_STATES)["in"], name, words, action=False)


def _draw_event(rng: random.Random) -> Proposition:
    """An achievement said as an event: a clause, so ``action`` is false."""
    kind = rng.random()
    if kind < 0.4:
        verb = rng.choice([v for v, _ in PLACE_VERBS if v in EVENTS])
        name, words = _thing(rng, PLACES, NUMBERED_PLACES)
    elif kind < 0.75:
        verb = rng.choice([v for v, _ in OBJECT_VERBS + MORE_OBJECT_VERBS if v in EVENTS])
        name, words = _thing(rng, OBJECTS, NUMBERED_OBJECTS)
    elif kind < 0.9:
        verb = rng.choice([v for v, _ in DEVICE_VERBS if v in EVENTS])
        name, words = _thing(rng, DEVICES, NUMBERED_DEVICES)
    else:
        verb = rng.choice([v for v, _ in STANDALONE_ACTIONS if v in EVENTS])
        return Proposition(verb, EVENTS[verb], action=False)
    return _about(verb, EVENTS[verb], name, words, action=False)


def _draw_condition(rng: random.Random) -> Proposition:
    if rng.random() < 0.2:
        return _draw_kept(rng, as_clause=True)
    kind = rng.random()
    if kind < 0.5:
        name, phrases = rng.choice(CONDITIONS)
        return Proposition(name, phrases, action=False)
    if kind < 0.8:
        verb, phrases = rng.choice(PLACE_STATES)
        name, words = _thing(rng, PLACES, NUMBERED_PLACES)
    else:
        verb, phrases = rng.choice(OBJECT_STATES)
        name, words = _thing(rng, OBJECTS, NUMBERED_OBJECTS)
    return _about(verb, phrases, name, words, action=False)


def _draw_one(rng: random.Random) -> Proposition:
    kind = rng.random()
    if kind < 0.4:
        verbs = PLACE_VERBS if kind < 0.32 else PLACE_TASK_VERBS
        verb, phrases = rng.choice(verbs)
        name, words = _thing(rng, PLACES, NUMBERED_PLACES)
    elif kind < 0.56:
        verb, phrases = rng.choice(OBJECT_VERBS if kind < 0.5 else MORE_OBJECT_VERBS)
        name, words = _thing(rng, OBJECTS, NUMBERED_OBJECTS)
    elif kind < 0.7:
        verb, phrases, things = rng.choice(TASK_VERBS)
        thing = rng.choice(things)
        return _about(verb, phrases, thing, thing.replace("_", " "), action=True)
    elif kind < 0.8:
        verb, phrases = rng.choice(DEVICE_VERBS)
        name, words = _thing(rng, DEVICES, NUMBERED_DEVICES)
    elif kind < 0.86:
        verb, phrases = rng.choice(STANDALONE_ACTIONS)
        return Proposition(verb, phrases, action=True, lasting=verb in LASTING_VERBS)
    else:
        name, phrases = rng.choice(CONDITIONS)
        return Proposition(name, phrases, action=False)
    return _about(verb, phrases, name, words, action=True)


def _about(verb: str, phrases: tuple[str, ...], name: str, words: str,
           action: bool) -> Proposition:
    """``verb_name``, said by each phrasing with the thing's words filled in."""
    filled = tuple(dict.fromkeys(p.format(x=words) for p in phrases))
    negated = tuple(p.format(x=words) for p in NEGATED.get(verb, ()))
    # "dock 3", as the numbered places' phrasings say it; "the kitchen"
    place = (words if words[-1].isdigit() else f"the {words}") if verb in BEING_AT else None
    return Proposition(f"{verb}_{name}", filled, action, lasting=action and verb in LASTING_VERBS,
                       negated=negated, place=place)


def _thing(rng: random.Random, plain, numbered) -> tuple[str, str]:
    if rng.random() < 0.35:
        stem, words = rng.choice(numbered)
        n = rng.randint(1, 12)
        return f"{stem}_{n}", f"{words} {n}"
    return rng.choice(plain)
