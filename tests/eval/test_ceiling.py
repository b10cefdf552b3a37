"""The label ceiling: what the data set's own labels leave a translator."""

from ara.data.normalize import Record
from ara.eval.ceiling import label_ceiling


def rec(nl: str, stl: str, row: int) -> Record:
    return Record(uid=str(row), nl=nl, stl=stl, aps=("prop_1", "prop_2"), source="navi",
                  form="lifted", row=row)


DONT = "don't (prop_1) or (prop_2)"


def test_conflicting_labels_cap_the_score():
    """Tests one sentence labelled two non-equivalent ways in the test side (2 : 1), and
    a training side whose majority picks the rarer test label."""
    test = [rec(DONT, "!prop_1 | prop_2", 0), rec(DONT, "!prop_1 | prop_2", 1),
            rec(DONT, "!F(prop_1) | prop_2", 2), rec("(prop_1) and (prop_2)", "prop_1 & prop_2", 3)]
    train = [rec(DONT, "!F(prop_1) | prop_2", 10), rec(DONT, "!F(prop_1) | prop_2", 11),
             rec(DONT, "!prop_1 | prop_2", 12)]
    ceiling = label_ceiling(test, train)
    assert (ceiling.records, ceiling.oracle, ceiling.train_majority) == (4, 3, 2)
    (conflict,) = ceiling.conflicts
    assert conflict.nl == DONT and conflict.train_choice == "!F(prop_1) | prop_2"


def test_equivalent_labels_are_one_class():
    """Tests that Spot, not the text, decides: G(!p) and !F(p) are the same answer."""
    test = [rec("never (prop_1)", "G(!prop_1)", 0), rec("never (prop_1)", "!F(prop_1)", 1)]
    ceiling = label_ceiling(test, [rec("never (prop_1)", "!F(prop_1)", 5)])
    assert (ceiling.oracle, ceiling.train_majority, ceiling.conflicts) == (2, 2, ())
