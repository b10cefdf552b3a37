"""Averaging LoRA adapters: the soup's update is the weighted mean of the parts' updates."""

import json

import pytest

from ara.errors import ConfigError
from ara.training.soup import SoupPart, average_adapters, reduce_rank

torch = pytest.importorskip("torch", reason="needs torch (make setup)")
peft = pytest.importorskip("peft", reason="needs peft (make setup)")


def tiny_model():
    from transformers import Gemma3ForCausalLM, Gemma3TextConfig

    torch.manual_seed(0)
    return Gemma3ForCausalLM(Gemma3TextConfig(
        vocab_size=64, hidden_size=32, intermediate_size=64, num_hidden_layers=2,
        num_attention_heads=2, num_key_value_heads=1, head_dim=16, query_pre_attn_scalar=16,
        sliding_window=64, max_position_embeddings=128))


def adapter(folder, seed, r, alpha, target_modules="all-linear"):
    """A LoRA with random A and B (a trained one, as far as averaging can tell)."""
    torch.manual_seed(seed)
    config = peft.LoraConfig(r=r, lora_alpha=alpha, target_modules=target_modules,
                             init_lora_weights=False)
    peft.get_peft_model(tiny_model(), config).save_pretrained(folder)
    return folder


def updates(folder):
    """Each adapted weight's change, after merging the adapter into the base."""
    base = dict(tiny_model().named_parameters())
    merged = peft.PeftModel.from_pretrained(tiny_model(), folder).merge_and_unload()
    return {name: (p - base[name]).detach() for name, p in merged.named_parameters()
            if not torch.equal(p, base[name])}


def test_the_soup_adds_the_updates_of_its_parts_in_proportion(tmp_path):
    a = adapter(tmp_path / "a", seed=1, r=4, alpha=8)
    b = adapter(tmp_path / "b", seed=2, r=2, alpha=8)   # another rank and scaling
    # PEFT writes target_modules from a set: two runs may list them in other orders.
    config_b = json.loads((b / "adapter_config.json").read_text())
    config_b["target_modules"] = sorted(config_b["target_modules"], reverse=True)
    (b / "adapter_config.json").write_text(json.dumps(config_b))
    soup = tmp_path / "soup"
    record = average_adapters([SoupPart(a, 3.0), SoupPart(b, 1.0)], soup)

    da, db, ds = updates(a), updates(b), updates(soup)
    assert set(ds) == set(da) == set(db) and len(ds) == 14   # 7 linear modules x 2 layers
    for name in ds:
        torch.testing.assert_close(ds[name], 0.75 * da[name] + 0.25 * db[name],
                                   rtol=1e-4, atol=1e-6)
    config = json.loads((soup / "adapter_config.json").read_text())
    assert config["r"] == 6 and config["lora_alpha"] / config["r"] == 2.0
    assert json.loads((soup / "soup.json").read_text())["parts"][0]["weight"] == 0.75
    assert record == json.loads((soup / "soup.json").read_text())


def best_rank(update, k):
    """The nearest rank-k matrix to ``update`` (Eckart-Young), from the full SVD."""
    u, sigma, vh = torch.linalg.svd(update.double())
    return (u[:, :k] * sigma[:k]) @ vh[:k]


def test_a_reduced_adapter_is_each_update_truncated_to_its_largest_singular_values(tmp_path):
    soup = tmp_path / "soup"
    average_adapters([SoupPart(adapter(tmp_path / "a", seed=1, r=4, alpha=8)),
                      SoupPart(adapter(tmp_path / "b", seed=2, r=4, alpha=8))], soup)
    full = updates(soup)

    record = reduce_rank(soup, 3, tmp_path / "r3")
    config = json.loads((tmp_path / "r3" / "adapter_config.json").read_text())
    assert config["r"] == 3 and config["lora_alpha"] / config["r"] == 2.0   # scaling kept
    kept = []
    for name, update in updates(tmp_path / "r3").items():
        torch.testing.assert_close(update.double(), best_rank(full[name], 3),
                                   rtol=1e-4, atol=1e-5)
        kept.append(float(update.norm() ** 2 / full[name].norm() ** 2))
    assert record["from_rank"] == 8 and record["rank"] == 3
    assert record["norm_kept"]["least"] == pytest.approx(min(kept), abs=1e-4)
    assert 0 < record["norm_kept"]["least"] < 1

    # At the adapter's own rank nothing is lost: the same updates, in other factors.
    assert reduce_rank(soup, 8, tmp_path / "r8")["norm_kept"]["least"] == pytest.approx(1.0)
    for name, update in updates(tmp_path / "r8").items():
        torch.testing.assert_close(update, full[name], rtol=1e-4, atol=1e-5)
    with pytest.raises(ConfigError, match="between 1 and the adapter's rank 8"):
        reduce_rank(soup, 9, tmp_path / "r9")


def test_adapters_that_cannot_be_averaged_are_refused_by_name(tmp_path):
    a = adapter(tmp_path / "a", seed=1, r=4, alpha=8)
    b = adapter(tmp_path / "b", seed=2, r=4, alpha=8, target_modules=["q_proj"])
    with pytest.raises(ConfigError, match="same modules"):
        average_adapters([SoupPart(a), SoupPart(b)], tmp_path / "soup")
    with pytest.raises(ConfigError, match="at least two"):
        average_adapters([SoupPart(a)], tmp_path / "soup")
    with pytest.raises(ConfigError, match="not a PEFT LoRA adapter"):
        average_adapters([SoupPart(a), SoupPart(tmp_path)], tmp_path / "soup")
    with pytest.raises(ConfigError, match="positive"):
        SoupPart(a, weight=0.0)


def test_ara_soup_makes_a_run_folder_that_export_can_read(tmp_path):
    """`ara soup` takes run folders and writes one: the soup's adapter and the first run's
    record with the parts added, which is what `ara export --run` reads."""
    from typer.testing import CliRunner

    from ara.cli import app

    runs = []
    for seed in (1, 2):
        run = tmp_path / f"run{seed}"
        adapter(run / "adapter", seed=seed, r=4, alpha=8)
        (run / "run.json").write_text(json.dumps({"base_model": {"path": "tiny"}, "seed": seed}))
        runs.append(run)
    args = ["soup", "--run", str(runs[0]), "--run", str(runs[1])]
    done = CliRunner().invoke(app, args + ["--out", str(tmp_path / "soup")])
    assert done.exit_code == 0, done.output
    record = json.loads((tmp_path / "soup" / "run.json").read_text())
    assert record["seed"] == 1 and record["soup"]["rank"] == 8
    assert (tmp_path / "soup" / "adapter" / "adapter_model.safetensors").is_file()

    wrong = CliRunner().invoke(app, args + ["--weight", "1", "--out", str(tmp_path / "x")])
    assert wrong.exit_code != 0 and "1 weights for 2 runs" in wrong.output
    bare = CliRunner().invoke(app, ["soup", "--run", str(runs[0]), "--run", str(tmp_path),
                                    "--out", str(tmp_path / "y")])
    assert bare.exit_code != 0 and "no run.json" in bare.output

    # --rank truncates the soup; with it, one run is enough (its adapter, reduced).
    done = CliRunner().invoke(app, args + ["--rank", "5", "--out", str(tmp_path / "soup5")])
    assert done.exit_code == 0, done.output
    record = json.loads((tmp_path / "soup5" / "run.json").read_text())
    assert record["soup"]["rank"] == 8 and record["reduced"]["rank"] == 5
    one = ["soup", "--run", str(tmp_path / "soup5"), "--out", str(tmp_path / "soup2")]
    alone = CliRunner().invoke(app, one)
    assert alone.exit_code != 0 and "at least two runs (or one and a rank" in alone.output
    done = CliRunner().invoke(app, one + ["--rank", "2"])
    assert done.exit_code == 0, done.output
    record = json.loads((tmp_path / "soup2" / "run.json").read_text())
    assert record["soup"]["rank"] == 8 and record["reduced"]["from_rank"] == 5


def test_export_refuses_at_once_what_would_fail_after_minutes(tmp_path):
    """Tests `ara export` on a folder that is no finished run, an unknown type and a
    negative parity: each is an error before any merging."""
    from conftest import run_ara

    adapter(tmp_path / "run" / "adapter", seed=1, r=4, alpha=8)
    (tmp_path / "run" / "run.json").write_text(json.dumps({"base_model": {"path": "tiny"}}))
    for args, message in [(["--run", str(tmp_path)], "has no run.json"),
                          (["--run", str(tmp_path / "run"), "--quant", "f16,q3"],
                           "unknown quantization ['q3']"),
                          (["--run", str(tmp_path / "run"), "--parity", "-3"],
                           "--parity takes a number of pairs")]:
        out = run_ara("export", *args)
        assert out.returncode == 2 and message in out.stderr, out.stderr
    assert not (tmp_path / "run" / "export").exists()
