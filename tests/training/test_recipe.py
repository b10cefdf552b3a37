"""The LoRA recipe on a tiny Gemma 3 built from a config: loss falls, resume, held-out check."""

import json
import shutil
from pathlib import Path

import pytest

from ara.data import registered_version
from ara.errors import ConfigError
from ara.training.config import TrainConfig
from ara.training.recipe import LoRAFinetuneRecipe, run_training


def tiny_config(model_dir, out, **overrides):
    # fp32 everywhere: "auto" takes bf16 on a CPU with AMX or AVX512-BF16, and equalities
    # of losses across runs need one precision on every machine.
    base = {"base_model": model_dir, "out": str(out), "seed": 0, "checkpoint_every": 3,
            "eval_pairs": 0, "max_steps": 6, "precision": "fp32",
            "lora": {"r": 4, "alpha": 8, "dropout": 0.0},
            "optim": {"lr": 5e-3, "batch_size": 4, "warmup_steps": 0},
            "data": {"forms": ["lifted"], "limit": 8}}
    return TrainConfig.from_dict({**base, **overrides})


def test_a_few_steps_lower_the_loss_and_resume_continues(tiny_gemma_dir, tmp_path):
    """Tests training on 8 pairs (2 batches, repeated over epochs): the loss falls,
    only the newest checkpoint is kept, and a resumed run picks up at its step."""
    config = tiny_config(tiny_gemma_dir, tmp_path / "run", keep_checkpoints=1,
                         optim={"lr": 5e-3, "batch_size": 4, "warmup_steps": 0, "epochs": 10})
    recipe = LoRAFinetuneRecipe(config)
    recipe.setup()
    losses = recipe.train()
    assert len(losses) == 6 and losses[-1] < losses[0]
    assert [p.name for p in (tmp_path / "run" / "checkpoints").iterdir()] == ["step_6"]
    log = [json.loads(x) for x in (tmp_path / "run" / "train_log.jsonl").read_text().splitlines()]
    assert [x["step"] for x in log] == list(range(1, 7)) and log[0]["tokens_per_s"] > 0
    run = json.loads((tmp_path / "run" / "run.json").read_text())
    assert run["data"]["split"] == "paper" and run["trainable_parameters"] > 0

    longer = TrainConfig.from_dict({**config.to_dict(), "max_steps": 8})
    resumed = LoRAFinetuneRecipe(longer, resume=True)
    resumed.setup()
    assert resumed.step == 6
    with open(tmp_path / "run" / "train_log.jsonl", "a") as torn:  # a session killed mid-line
        torn.write('{"step": 7, "lo')
    assert len(resumed.train()) == 2 and resumed.step == 8
    lines = (tmp_path / "run" / "train_log.jsonl").read_text().splitlines()
    assert [json.loads(x)["step"] for x in lines[-2:]] == [7, 8]  # none glued to the half line
    whole = resumed.save_checkpoint() / "step.json"
    written = whole.stat().st_mtime_ns
    resumed.save_checkpoint()  # a whole checkpoint is not written again in place
    assert whole.stat().st_mtime_ns == written
    # The run's summary reads its log, so a session killed outright (which records no
    # time of its own) still counts: the first loss is step 1's, the seconds every step's.
    summary = run_training(TrainConfig.from_dict({**config.to_dict(), "max_steps": 9}),
                           resume=True)
    log = [json.loads(x) for x in (tmp_path / "run" / "train_log.jsonl").read_text().splitlines()
           if x.endswith("}")]  # not the half line
    assert summary["steps"] == 9 and len(log) == 9 and summary["first_loss"] == log[0]["loss"]
    assert summary["step_seconds"] == round(sum(x["seconds"] for x in log), 1) > 0
    with pytest.raises(Exception, match="already holds a run"):
        LoRAFinetuneRecipe(config)
    # Pinning the version the run started on (unpinned) is no change.
    pinned = {**config.to_dict()["data"], "version": registered_version("paper", 0)}
    again = LoRAFinetuneRecipe(TrainConfig.from_dict({**config.to_dict(), "data": pinned,
                                                      "max_steps": 9}), resume=True)
    again.setup()
    assert again.step == 9
    # Resuming with another learning rate would silently train something else.
    changed = TrainConfig.from_dict({**config.to_dict(), "optim": {**config.to_dict()["optim"],
                                                                   "lr": 1e-3}})
    with pytest.raises(ConfigError, match=r"optim.lr: 0.005 -> 0.001"):
        LoRAFinetuneRecipe(changed, resume=True)


def test_a_run_killed_before_its_first_checkpoint_resumes_from_step_0(tiny_gemma_dir,
                                                                     tmp_path):
    """Tests `--resume` on a run that wrote its record and a few log lines, then died
    before its first checkpoint: it starts over, and its log holds each step once."""
    config = tiny_config(tiny_gemma_dir, tmp_path / "run", max_steps=2, checkpoint_every=5)
    recipe = LoRAFinetuneRecipe(config)
    recipe.setup()
    recipe.train()  # stops at step 2, as a run killed before its first checkpoint
    assert not (tmp_path / "run" / "checkpoints").exists()
    resumed = LoRAFinetuneRecipe(config, resume=True)
    with pytest.warns(UserWarning, match="no checkpoint yet: training starts again"):
        resumed.setup()
    assert resumed.step == 0 and len(resumed.train()) == 2
    log = (tmp_path / "run" / "train_log.jsonl").read_text().splitlines()
    assert [json.loads(x)["step"] for x in log] == [1, 2]


def test_resume_refuses_a_folder_with_no_run_and_a_finished_run_without_checkpoints(
        tiny_gemma_dir, tmp_path):
    """Both before the model loads: the recipe refuses them as it is made."""
    config = tiny_config(tiny_gemma_dir, tmp_path / "run", max_steps=1)
    with pytest.raises(ConfigError, match="holds no run \\(no run.json\\): drop --resume"):
        LoRAFinetuneRecipe(config, resume=True)
    run_training(config)
    shutil.rmtree(tmp_path / "run" / "checkpoints")  # to save space
    with pytest.raises(ConfigError, match="a finished run \\(adapter/\\) with no checkpoint"):
        LoRAFinetuneRecipe(config, resume=True)


def test_a_base_model_that_is_not_here_is_refused_before_anything_loads(tmp_path):
    """The 12B config names /models/gemma-3-12b-it: on a machine without it, one line."""
    config = TrainConfig(base_model=str(tmp_path / "gemma-3-12b-it"), out=str(tmp_path / "r"))
    with pytest.raises(ConfigError, match="is no folder here, nor a hub id in the local cache"):
        LoRAFinetuneRecipe(config)


def test_too_few_records_for_one_optimizer_step_are_refused(tiny_gemma_dir, tmp_path):
    config = tiny_config(tiny_gemma_dir, tmp_path / "run",
                         optim={"lr": 5e-3, "batch_size": 8, "grad_accum": 2})
    with pytest.raises(ConfigError, match="8 training records make 1 batches of 8 an epoch: "
                                          "1 epochs of them are fewer than one optimizer step "
                                          "of grad_accum 2"):
        LoRAFinetuneRecipe(config).setup()


def test_steps_that_span_an_epoch_end_resume_where_they_stood(tiny_gemma_dir, tmp_path):
    """Tests grad_accum 2 over 3 batches an epoch, so steps 2 and 5 span an epoch's end:
    every epoch is taken whole, once (the position comes from the micro-batches taken;
    counting whole steps an epoch skipped the third), and a run resumed from step 3
    takes the batches an uninterrupted one takes."""
    config = tiny_config(tiny_gemma_dir, tmp_path / "run", max_steps=None, checkpoint_every=3,
                         keep_checkpoints=2,
                         optim={"lr": 5e-3, "batch_size": 4, "grad_accum": 2, "epochs": 4,
                                "warmup_steps": 0},
                         data={"forms": ["lifted"], "limit": 12})
    whole = LoRAFinetuneRecipe(config)
    whole.setup()
    assert len(whole.train()) == 6
    whole.save_checkpoint()
    log = tmp_path / "run" / "train_log.jsonl"
    steps = [json.loads(x) for x in log.read_text().splitlines()]
    # 12 batches in 4 epochs of 3, two a step: the epoch each step ends in, none skipped
    assert [x["epoch"] for x in steps] == [0, 1, 1, 2, 3, 3]
    uninterrupted = [x["loss"] for x in steps]
    shutil.rmtree(tmp_path / "run" / "checkpoints" / "step_6")  # as if killed after step 5
    log.write_text("".join(x + "\n" for x in log.read_text().splitlines()[:3]))
    resumed = LoRAFinetuneRecipe(config, resume=True)
    resumed.setup()
    assert resumed.step == 3
    assert resumed.train() == pytest.approx(uninterrupted[3:], rel=1e-4)


@pytest.mark.slow  # the harness runs a real model by default (test_user_data)
def test_adapter_and_heldout_check_through_the_harness(tiny_gemma_dir, tmp_path):
    """Tests the saved adapter and the held-out check, with prompts of 0 and 2 worked
    examples: even random weights give valid formulas under the grammar."""
    config = tiny_config(tiny_gemma_dir, tmp_path / "run", max_steps=2, eval_pairs=2,
                         data={"forms": ["lifted"], "limit": 8, "shots": [0, 2]})
    recipe = LoRAFinetuneRecipe(config)
    recipe.setup()
    recipe.train()
    log = [json.loads(x) for x in (tmp_path / "run" / "train_log.jsonl").read_text().splitlines()]
    assert {x["shots"] for x in log} <= {0, 2}
    adapter = recipe.save_adapter()
    assert (adapter / "adapter_config.json").is_file()
    report = recipe.heldout_check()
    assert report["pairs"] == 2 and set(report["by_shots"]) == {"0", "2"}
    assert report["validity"] == 1.0


def test_a_bf16_run_keeps_its_adapter_and_loss_in_fp32(tiny_gemma_dir, tmp_path):
    """Tests ``precision: bf16``: the frozen base in bf16, the LoRA weights (what is
    trained and saved) in fp32, a first loss as fp32's (the golden run's first batch) and
    falling, each step logged as bf16, and the held-out check (which casts to fp32 on a
    CPU) generating from it."""
    import torch

    from ara.training.tiny import GOLDEN_RUN

    config = TrainConfig.from_dict({**GOLDEN_RUN, "base_model": tiny_gemma_dir,
                                    "out": str(tmp_path / "run"), "precision": "bf16",
                                    "max_steps": 3, "eval_pairs": 1})
    recipe = LoRAFinetuneRecipe(config)
    recipe.setup()
    losses = recipe.train()
    assert {p.dtype for p in recipe.model.parameters() if p.requires_grad} == {torch.float32}
    assert {p.dtype for p in recipe.model.parameters() if not p.requires_grad} == {
        torch.bfloat16}
    assert json.loads((tmp_path / "run" / "run.json").read_text())["dtype"] == "bfloat16"
    log = (tmp_path / "run" / "train_log.jsonl").read_text().splitlines()
    assert {json.loads(line)["dtype"] for line in log} == {"bfloat16"}
    # A fresh LoRA adds nothing, so the first step is the base model's: bf16 rounding only.
    golden = json.loads(Path(__file__).with_name("golden_losses.json").read_text())
    assert losses[0] == pytest.approx(golden["losses"][0], rel=2e-2)
    assert losses[-1] < losses[0]
    assert recipe.heldout_check()["validity"] == 1.0


@pytest.mark.slow  # the default tier warm-starts a stage in test_stage_runner
def test_a_warm_start_continues_from_a_finished_adapter(tiny_gemma_dir, tmp_path):
    """Tests ``init_adapter``: a second run starting from the first run's adapter begins
    at the loss the first run ended with (the same batch), not at a fresh LoRA's."""
    import torch

    first = tiny_config(tiny_gemma_dir, tmp_path / "first",
                        optim={"lr": 5e-3, "batch_size": 8, "warmup_steps": 0, "epochs": 10})
    trained = LoRAFinetuneRecipe(first)
    trained.setup()
    trained.train()
    adapter = trained.save_adapter()

    def first_loss(**overrides):
        config = TrainConfig.from_dict({**first.to_dict(), "max_steps": 1, **overrides})
        recipe = LoRAFinetuneRecipe(config)
        recipe.setup()
        torch.manual_seed(0)
        return recipe.train()[0], recipe

    # One batch of 8 is the whole data (limit 8): every run's first step sees the same rows.
    warm, recipe = first_loss(out=str(tmp_path / "warm"), init_adapter=str(adapter))
    cold, _ = first_loss(out=str(tmp_path / "cold"))
    ended, _ = first_loss(out=str(tmp_path / "again"), init_adapter=str(adapter))
    assert warm == pytest.approx(ended) and warm < cold
    run = json.loads((tmp_path / "warm" / "run.json").read_text())
    assert run["init_adapter"]["path"] == str(adapter) and len(run["init_adapter"]["sha256"]) == 64

    with pytest.raises(ConfigError, match="no adapter_config.json"):
        LoRAFinetuneRecipe(TrainConfig.from_dict({**first.to_dict(), "out": str(tmp_path / "x"),
                                                  "init_adapter": str(tmp_path)}))
    other_shape = TrainConfig.from_dict({**first.to_dict(), "out": str(tmp_path / "y"),
                                         "init_adapter": str(adapter),
                                         "lora": {"r": 8, "alpha": 8, "dropout": 0.0}})
    with pytest.raises(ConfigError, match="another LoRA shape"):
        LoRAFinetuneRecipe(other_shape).setup()
    other = TrainConfig.from_dict({**first.to_dict(), "out": str(tmp_path / "z"),
                                   "init_adapter": str(adapter),
                                   "lora": {**first.to_dict()["lora"],
                                            "target_modules": ["q_proj"]}})
    with pytest.raises(ConfigError, match="target_modules"):
        LoRAFinetuneRecipe(other).setup()
    # Dropout is a training setting, not a shape: a warm start trains with its own.
    dropped = LoRAFinetuneRecipe(TrainConfig.from_dict({
        **first.to_dict(), "out": str(tmp_path / "d"), "init_adapter": str(adapter),
        "lora": {**first.to_dict()["lora"], "dropout": 0.3}}))
    dropped.setup()
    rates = {m.p for name, m in dropped.model.named_modules()
             if isinstance(m, torch.nn.Dropout) and "lora_dropout" in name}
    assert rates == {0.3}


@pytest.mark.slow  # converts and quantizes a 262k-vocabulary model: about a minute
def test_export_gguf_loads_in_llama_cpp_and_matches_hf_logits(tiny_gemma_dir, tmp_path):
    """Tests train -> merge -> GGUF (f32) -> q8_0 and the GGUF LoRA, then that llama.cpp
    and transformers compute the same next-token scores from the exported weights, and
    that the GGUF LoRA reads back as the trained adapter.

    Random weights give near-uniform scores, so greedy answers are a coin toss under any
    rounding; the score vectors themselves must still agree.
    """
    import numpy as np

    from ara.eval.translate.backends.hf_backend import HFBackend
    from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend
    from ara.training.export import export_run

    config = tiny_config(tiny_gemma_dir, tmp_path / "run", max_steps=2)
    recipe = LoRAFinetuneRecipe(config)
    recipe.setup()
    recipe.train()
    recipe.save_adapter()
    manifest = export_run(tmp_path / "run", ("f32", "q8_0"), lora_gguf=True, outtype="f32")
    export = tmp_path / "run" / "export"
    assert set(manifest["files"]) == {"model-f32.gguf", "model-q8_0.gguf", "lora.gguf"}
    LlamaCppBackend(str(export / "model-q8_0.gguf"))  # loads
    llama = LlamaCppBackend(str(export / "model-f32.gguf"))
    hf = HFBackend(str(export / "merged-hf"))
    prompt = "NL: always (prop_1)\nPropositions: prop_1\nSTL:"
    tokens = llama.llm.tokenize(prompt.encode(), add_bos=True, special=False)
    assert tokens == hf.tokenizer(prompt, add_special_tokens=True)["input_ids"]
    ours, _ = llama._feed_prompt(tokens)
    theirs, _ = hf._feed_prompt(tokens)
    assert np.corrcoef(ours, theirs)[0, 1] > 0.999
    # The GGUF LoRA read back as PEFT, as a warm start from a shipped file reads it: the
    # trained weights under their own names, to f16's precision.
    from safetensors.numpy import load_file

    from ara.training.export import peft_from_gguf

    back = load_file(peft_from_gguf(export / "lora.gguf", tmp_path / "peft")
                     / "adapter_model.safetensors")
    trained = load_file(tmp_path / "run" / "adapter" / "adapter_model.safetensors")
    assert back.keys() == trained.keys()
    for name, weights in trained.items():
        np.testing.assert_allclose(back[name], weights, rtol=1e-3, atol=1e-6, err_msg=name)


@pytest.mark.slow  # a speed-up's equivalence; the golden losses pin training in the default tier
def test_the_answer_only_loss_equals_the_loss_over_every_position(tiny_gemma_dir):
    """The instructions every prompt starts with run once per batch, and the output layer
    sees only answer positions; loss and LoRA gradients must match a plain forward
    that computes every position's logits."""
    import torch
    from peft import LoraConfig, get_peft_model
    from transformers import AutoModelForCausalLM, AutoTokenizer

    from ara.data import load_split
    from ara.training.dataset import answer_loss, collate, encode, shared_prefix_length

    tokenizer = AutoTokenizer.from_pretrained(tiny_gemma_dir)
    records = load_split("paper", 0).records("train", "lifted")[:4]
    batch = collate(encode(records, tokenizer), tokenizer.pad_token_id)
    assert 20 < shared_prefix_length(batch) < batch["input_ids"].shape[1]
    torch.manual_seed(0)
    model = get_peft_model(AutoModelForCausalLM.from_pretrained(tiny_gemma_dir),
                           LoraConfig(r=4, lora_alpha=8, target_modules="all-linear",
                                      init_lora_weights=False))

    def loss_and_grads(share):
        model.zero_grad()
        loss = answer_loss(model, batch, share_prefix=share)
        loss.backward()
        return loss.item(), [p.grad.clone() for p in model.parameters() if p.requires_grad]

    def reference():
        """Every position's logits, the answer tokens' cross-entropy averaged."""
        model.zero_grad()
        logits = model(input_ids=batch["input_ids"],
                       attention_mask=batch["attention_mask"]).logits[:, :-1]
        loss = torch.nn.functional.cross_entropy(
            logits.float().reshape(-1, logits.shape[-1]),
            batch["labels"][:, 1:].reshape(-1), ignore_index=-100)
        loss.backward()
        return loss.item(), [p.grad.clone() for p in model.parameters() if p.requires_grad]

    full_loss, full_grads = reference()
    for share in (False, True):
        loss, grads = loss_and_grads(share)
        assert loss == pytest.approx(full_loss, rel=1e-5)
        for a, b in zip(full_grads, grads, strict=True):
            torch.testing.assert_close(a, b, rtol=1e-4, atol=1e-6)


def test_two_steps_reproduce_the_golden_losses(tiny_gemma_dir, tmp_path):
    """The losses of scripts/golden_losses.py's run, within float tolerance: a change to
    the data order, the prompt, the loss or the LoRA setup shows up here."""
    from pathlib import Path

    from ara.training.tiny import GOLDEN_RUN

    golden = json.loads(Path(__file__).with_name("golden_losses.json").read_text())
    assert golden["run"] == GOLDEN_RUN, "GOLDEN_RUN changed: rerun scripts/golden_losses.py"
    config = TrainConfig.from_dict({**GOLDEN_RUN, "base_model": tiny_gemma_dir,
                                    "out": str(tmp_path / "run")})
    recipe = LoRAFinetuneRecipe(config)
    recipe.setup()
    assert recipe.train() == pytest.approx(golden["losses"], rel=1e-4)


@pytest.mark.slow  # the golden losses pin a step of the default tier's training
def test_a_step_of_several_micro_batches_logs_all_of_them(tiny_gemma_dir, tmp_path):
    """With grad_accum 2, one logged step covers both micro-batches (their shot counts,
    their summed tokens and time, their mean loss), not the last one alone."""
    config = tiny_config(tiny_gemma_dir, tmp_path / "run", max_steps=2,
                         optim={"lr": 5e-3, "batch_size": 2, "grad_accum": 2,
                                "warmup_steps": 0, "epochs": 2},
                         data={"forms": ["lifted"], "limit": 8, "shots": [0, 2]})
    recipe = LoRAFinetuneRecipe(config)
    recipe.setup()
    losses = recipe.train()
    log = [json.loads(x) for x in (tmp_path / "run" / "train_log.jsonl").read_text().splitlines()]
    assert [x["step"] for x in log] == [1, 2] and len(losses) == 2
    assert all(isinstance(x["shots"], list) and len(x["shots"]) == 2 for x in log)
    assert [x["loss"] for x in log] == [round(v, 5) for v in losses]


@pytest.mark.slow  # saving a merged 262k-vocabulary model takes seconds; the export test merges too
def test_merging_an_adapter_saved_without_a_tokenizer_takes_the_bases(tiny_gemma_dir, tmp_path):
    """A soup of committed adapters has no tokenizer beside it (runs save one, the
    committed records do not): the merged folder gets the base model's, so that
    `ara export` of such a soup still makes a complete HF folder."""
    from peft import LoraConfig, get_peft_model
    from transformers import AutoModelForCausalLM, AutoTokenizer

    from ara.training.export import merge_adapter

    model = AutoModelForCausalLM.from_pretrained(tiny_gemma_dir)
    get_peft_model(model, LoraConfig(r=2, lora_alpha=4, target_modules="all-linear")
                   ).save_pretrained(tmp_path / "adapter")
    assert not (tmp_path / "adapter" / "tokenizer.json").exists()
    merged = merge_adapter(str(tiny_gemma_dir), str(tmp_path / "adapter"), tmp_path / "merged")
    ours, base = (AutoTokenizer.from_pretrained(d) for d in (merged, tiny_gemma_dir))
    assert ours("always ( prop_1 )")["input_ids"] == base("always ( prop_1 )")["input_ids"]


def test_your_own_pairs_join_the_training_records(tiny_gemma_dir, tmp_path, monkeypatch):
    """Tests ``data.pairs``: a user's file becomes training records of the source
    ``pairs``, weighted by ``repeat``, its hash recorded; the shipped adapter is a
    warm start by its name."""
    pairs = tmp_path / "lab.jsonl"
    pairs.write_text('{"nl": "Sweep field 2.", "aps": ["at_field_2"], '
                     '"stl": "G(F(at_field_2))"}\n'
                     '{"nl": "Hold at the shed.", "aps": ["at_shed"], "stl": "G(at_shed)"}\n')
    config = tiny_config(tiny_gemma_dir, tmp_path / "run", max_steps=1,
                         data={"forms": ["grounded"], "limit": 4, "pairs": str(pairs),
                               "repeat": {"pairs": 3}})
    recipe = LoRAFinetuneRecipe(config)
    recipe.setup()
    assert len(recipe.train_records) == 4 + 2 * 3
    assert sum(r.source == "pairs" for r in recipe.train_records) == 6
    run = json.loads((tmp_path / "run" / "run.json").read_text())
    assert len(run["data"]["pairs_sha256"]) == 64
    monkeypatch.setenv("ARA_CACHE", str(tmp_path / "cache"))  # where it is converted to PEFT
    shipped = TrainConfig.from_dict({**config.to_dict(), "init_adapter": "finetuned"})
    assert (shipped.init_adapter_folder / "adapter_config.json").is_file()
    # Pairs of a form the run does not train on would be dropped without a word.
    lifted_only = tiny_config(tiny_gemma_dir, tmp_path / "run2", max_steps=1,
                              data={"forms": ["lifted"], "limit": 4, "pairs": str(pairs)})
    with pytest.raises(ConfigError, match=r"its 2 pairs are \['grounded'\].*add grounded"):
        LoRAFinetuneRecipe(lifted_only).setup()


def test_a_lab_pairs_config_names_a_file_that_exists():
    from pathlib import Path

    root = Path(__file__).parents[2]
    config = TrainConfig.from_yaml(root / "training" / "configs" / "gemma3_270m_lab_pairs.yaml")
    assert (root / config.data.pairs).is_file() and config.init_adapter == "finetuned"
