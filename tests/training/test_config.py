"""Run configs: YAML sections into dataclasses, clear errors, round trips."""

from pathlib import Path

import pytest

from ara.errors import ConfigError
from ara.training.config import TrainConfig

CONFIGS = sorted(Path(__file__).parents[2].joinpath("training", "configs").glob("*.yaml"))


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.name)
def test_shipped_configs_load_and_round_trip(path):
    """Tests every committed YAML config through load, to_dict and from_dict: a single
    run as it is, a staged recipe stage by stage."""
    import yaml

    from ara.training.stages import StagedRecipe, is_staged

    data = yaml.safe_load(path.read_text())
    if is_staged(data):
        recipe = StagedRecipe.from_dict(data)
        configs = [recipe.train_config(s) for s in recipe.stages if s.kind == "train"]
        assert configs
    else:
        configs = [TrainConfig.from_yaml(path)]
    for config in configs:
        assert TrainConfig.from_dict(config.to_dict()) == config


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"lora": {"alhpa": 8}}, r"unknown key lora.alhpa. Did you mean 'alpha'\?"),  # typo
        ({"optimizer": {}}, "unknown key optimizer"),
        ({"optim": {"lr": 0}}, r"optim.lr must be a number > 0, got 0"),
        # YAML reads 2e-4 as text: named, not a TypeError deep in training
        ({"optim": {"lr": "2e-4"}}, r"optim.lr must be .* got '2e-4' \(YAML reads"),
        ({"optim": {"batch_size": 8.5}}, r"optim.batch_size must be a whole number >= 1"),
        ({"lora": {"dropout": 1.0}}, r"lora.dropout must be a number >= 0 and < 1"),
        ({"lora": {"target_modules": 5}}, "all-linear or a list of module names"),
        ({"data": {"shots": 5}}, r"data.shots must be a list, e.g. \[5\]"),
        ({"checkpoint_every": True}, "checkpoint_every must be a whole number"),
        ({"data": {"forms": ["lifted", "raw"]}}, "lifted and/or grounded"),
        ({"max_steps": 0}, r"max_steps must be a whole number >= 1 \(or null\)"),
        ({"lora": 3}, "lora must be a mapping"),
        ({"data": {"shots": [0, -5]}}, "counts >= 0"),
        ({"data": {"shots": []}}, "counts >= 0"),
        ({"data": {"version": "v3"}}, "12 hex digits"),
        ({"keep_checkpoints": 0}, "keep_checkpoints must be a whole number >= 1"),
        ({"data": {"repeat": {"nl2tl_timed_train": 0}}}, "counts >= 1"),
        ({"data": {"repeat": ["nl2tl_timed_train"]}}, "counts >= 1"),
    ],
)
def test_bad_configs_say_what_is_wrong(data, message):
    """Tests that misspelt keys and out-of-range values raise with the fix."""
    with pytest.raises(ConfigError, match=message):
        TrainConfig.from_dict(data)


def test_missing_file_is_a_clear_error(tmp_path):
    """Tests the message for a config path that does not exist."""
    with pytest.raises(ConfigError, match="config file not found"):
        TrainConfig.from_yaml(tmp_path / "nope.yaml")
