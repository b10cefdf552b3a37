"""LoRA fine-tuning recipe: reads top to bottom, like torchtune's single-device recipes.

    ara train --config training/configs/gemma3_270m_lora_cpu.yaml [--max-steps N] [--resume]

Runs unchanged on one CPU, one GPU, or several through ``accelerate launch``. The run
folder receives ``run.json`` (config, data and grammar versions, base-model hash, seed,
git commit), ``train_log.jsonl`` (one line per step: loss, learning rate, worked
examples shown, tokens/s, seconds),
``checkpoints/step_N`` (resumable), ``adapter/`` (the final LoRA) and
``heldout.json`` (validity and accuracy through the evaluation harness).
"""

from __future__ import annotations

import json
import random
import shutil
import time
import warnings
from pathlib import Path

import torch
from tqdm import tqdm

from ara import __version__
from ara.errors import ConfigError
from ara.provenance import write_atomic
from ara.training.config import TrainConfig, read_config
from ara.training.dataset import (
    answer_loss_sum,
    batch_shots,
    batches,
    collate,
    encode,
    own_pairs,
    repeat_sources,
    shot_rng,
)
from ara.training.hf_model import forward_in, load_tokenizer, training_dtype, warm_started
from ara.training.run_folder import (
    adapter_identity,
    checkpoint_folder,
    exclusive,
    log_summary,
    refuse_changed_config,
    refuse_changed_data,
    whole_checkpoints,
)


class LoRAFinetuneRecipe:
    """One fine-tuning run of ``config``.

    Args:
        config: The run's settings; checked on construction.
        resume: Continue from the newest checkpoint in ``config.out``.
    """

    def __init__(self, config: TrainConfig, resume: bool = False) -> None:
        self.config = config
        self.out = Path(config.out)
        self.resume = resume
        if self.out.joinpath("run.json").exists() and not resume:
            raise ConfigError(f"{self.out} already holds a run: pass --resume or another out")
        if resume and self.out.joinpath("run.json").exists():
            refuse_changed_config(self.out / "run.json", config)
        if config.init_adapter and not Path(config.init_adapter_folder,
                                            "adapter_config.json").is_file():
            raise ConfigError(
                f"init_adapter: {config.init_adapter} holds no adapter_config.json; name the "
                "adapter/ folder of a finished run (train that run first)")
        if config.base_model != "default":  # the default is prepared in setup()
            _check_base_model(config.base_model)
        if resume and not whole_checkpoints(self.out):  # before minutes of loading
            if not self.out.joinpath("run.json").is_file():
                raise ConfigError(f"--resume: {self.out} holds no run (no run.json): drop "
                                  "--resume to start one")
            if self.out.joinpath("adapter").is_dir():
                raise ConfigError(f"--resume: {self.out} is a finished run (adapter/) with no "
                                  "checkpoint left to go on from: train into another out "
                                  "folder")
        self.step = 0

    # -- setup: each part needs the ones before it ------------------------------------
    def setup(self) -> None:
        from accelerate import Accelerator
        from accelerate.utils import set_seed

        # The accelerator first: it decides the device and process group everything uses.
        # The scheduler steps once an optimizer step, by hand: accelerate's own stepping
        # assumes each process has a batch of its own and steps it once per process,
        # where here the processes split one global batch (the schedule ran N times
        # too fast on N GPUs).
        self.accelerator = Accelerator(gradient_accumulation_steps=self.config.optim.grad_accum,
                                       step_scheduler_with_optimizer=False)
        set_seed(self.config.seed)
        self.model_dir = self._base_model_dir()
        self.dtype = training_dtype(self.config.precision, self.accelerator.device)
        self.dtype_name = str(self.dtype).removeprefix("torch.")
        # The tokenizer before the data (examples are token ids), the data before the
        # schedule (its length sets the number of steps).
        self.tokenizer = load_tokenizer(self.model_dir)
        # The first use of a registered split prepares it; one process writes it.
        with self.accelerator.main_process_first():
            self.train_records, self.split = self._load_data()
        optim = self.config.optim
        # Micro-batches: an optimizer step takes grad_accum of them, across an epoch's
        # end where they do not divide it.
        self.batches_per_epoch = -(-len(self.train_records) // optim.batch_size)
        self.total_steps = self.config.steps_for(len(self.train_records))
        if not self.total_steps:
            raise ConfigError(
                f"{len(self.train_records)} training records make {self.batches_per_epoch} "
                f"batches of {optim.batch_size} an epoch: {optim.epochs} epochs of them are "
                f"fewer than one optimizer step of grad_accum {optim.grad_accum}; train on more "
                "records (data.forms, data.limit) or epochs, or lower batch_size or grad_accum")
        model = self._lora_model()
        optimizer = torch.optim.AdamW([p for p in model.parameters() if p.requires_grad],
                                      lr=self.config.optim.lr,
                                      weight_decay=self.config.optim.weight_decay)
        scheduler = torch.optim.lr_scheduler.LambdaLR(optimizer, self._lr_factor)
        self.model, self.optimizer, self.scheduler = self.accelerator.prepare(
            model, optimizer, scheduler)
        if self.resume:
            self._load_checkpoint()
        elif self.accelerator.is_main_process:
            self.out.mkdir(parents=True, exist_ok=True)
            # Whole or not at all: a later rerun and `--status` read it.
            write_atomic(self.out / "run.json",
                         json.dumps(self._provenance(), indent=2, sort_keys=True) + "\n")
        self.accelerator.wait_for_everyone()

    def _base_model_dir(self) -> str:
        if self.config.base_model == "default":
            from ara.training.hf_model import prepare_base_model

            return str(prepare_base_model())
        return self.config.base_model

    def _load_data(self):
        from ara.data import load_or_prepare, load_split

        data = self.config.data
        # The registered version is deterministic: a fresh clone prepares it rather than
        # stopping one command short of training; a pinned older one must exist.
        split = (load_or_prepare(data.split, data.seed) if data.version is None
                 else load_split(data.split, data.seed, version=data.version))
        if self.resume and self.out.joinpath("run.json").exists():
            refuse_changed_data(self.out / "run.json", data, split.version)
        records = [r for f in self.config.data.forms for r in split.records("train", f)]
        if self.config.data.limit:
            records = records[: self.config.data.limit]
        if data.pairs:
            mine = own_pairs(data.pairs)
            kept = [r for r in mine if r.form in data.forms]
            if mine and not kept:
                forms = sorted({r.form for r in mine})
                raise ConfigError(f"{data.pairs}: its {len(mine)} pairs are {forms}, and "
                                  f"data.forms trains on {list(data.forms)}: add {forms[0]}")
            records += kept
        return repeat_sources(records, self.config.data.repeat), split

    def _lora_model(self):
        from peft import LoraConfig, get_peft_model
        from transformers import AutoModelForCausalLM

        dtype = self.dtype
        base = AutoModelForCausalLM.from_pretrained(self.model_dir, local_files_only=True,
                                                    dtype=dtype)
        lora = self.config.lora
        if self.config.init_adapter:
            return warm_started(base, str(self.config.init_adapter_folder), lora)
        return get_peft_model(base, LoraConfig(
            r=lora.r, lora_alpha=lora.alpha, lora_dropout=lora.dropout,
            target_modules=lora.target_modules, task_type="CAUSAL_LM"))

    def _lr_factor(self, step: int) -> float:
        warm = self.config.optim.warmup_steps
        if step < warm:
            return (step + 1) / warm
        return max(0.0, (self.total_steps - step) / max(1, self.total_steps - warm))

    def _provenance(self) -> dict:
        from ara.grammars import GRAMMAR_VERSION
        from ara.provenance import git_commit, sha256_file

        manifest = Path(self.model_dir, "ara_model.json")
        base_hash = json.loads(manifest.read_text())["gguf_sha256"] if manifest.exists() else None
        return {"config": self.config.to_dict(), "ara_version": __version__,
                "git_commit": git_commit(), "grammar_version": GRAMMAR_VERSION,
                "data": {"split": self.config.data.split, "version": self.split.version,
                         "train_examples": len(self.train_records),
                         **({"pairs_sha256": sha256_file(self.config.data.pairs)}
                            if self.config.data.pairs else {})},
                "base_model": {"path": self.model_dir, "gguf_sha256": base_hash},
                "processes": self.accelerator.num_processes,
                "dtype": self.dtype_name,
                "init_adapter": adapter_identity(self.config.init_adapter_folder),
                "trainable_parameters": sum(p.numel() for p in self.model.parameters()
                                            if p.requires_grad)}

    # -- train ----------------------------------------------------------------------
    def train(self) -> list[float]:
        """Run the optimizer steps left; returns the loss of each step taken."""
        cfg, pad = self.config, self.tokenizer.pad_token_id or 0
        acc = self.accelerator
        # With several processes each takes its share of every batch (batch_size is the
        # global batch); their summed losses over the batch's answer tokens make the same
        # loss, and the same gradient, as one process with the whole batch.
        world, rank = acc.num_processes, acc.process_index
        losses: list[float] = []
        bar = tqdm(total=self.total_steps, initial=self.step, desc="training", unit="step",
                   disable=not acc.is_main_process, dynamic_ncols=True)
        log = self._open_log() if acc.is_main_process else None
        self.model.train()
        # One optimizer step spans grad_accum micro-batches: its log line sums their
        # time and tokens and averages their losses.
        micro_losses: list[float] = []
        micro_shots: list[int] = []
        tokens, start = 0, time.perf_counter()
        # Where the micro-batches stand: a resumed run starts at a step's first one.
        taken = self.step * cfg.optim.grad_accum
        try:
            while self.step < self.total_steps:
                epoch, skip = divmod(taken, self.batches_per_epoch)
                for index, micro in enumerate(batches(self.train_records, cfg.optim.batch_size,
                                                      cfg.seed, epoch, skip), start=skip):
                    taken += 1
                    if not micro_losses:
                        start = time.perf_counter()
                    shots = self._shots(micro, epoch, index)
                    # A process left without rows (a short last batch) runs one row at
                    # weight 0, so that every process meets in the gradient exchange.
                    mine = micro[rank::world]
                    weight = 1.0 if mine else 0.0
                    examples = encode(mine or micro[:1], self.tokenizer, shots)
                    batch = {k: v.to(acc.device) for k, v in collate(examples, pad).items()}
                    with acc.accumulate(self.model):
                        with forward_in(self.dtype, self.model, acc.device):
                            total, count = answer_loss_sum(self.model, batch)
                        # One exchange per micro-batch: the batch's loss sum, its answer
                        # tokens and all its tokens, over every process.
                        loss_sum, counted, batch_tokens = acc.reduce(weight * torch.stack([
                            total.detach(), total.new_tensor(float(count)),
                            batch["attention_mask"].sum().to(total)]), "sum")
                        # DDP averages gradients over processes: scale back to the sum
                        acc.backward(total * weight * world / counted)
                        self.optimizer.step()
                        if acc.sync_gradients:
                            self.scheduler.step()
                        self.optimizer.zero_grad()
                    micro_losses.append(float(loss_sum / counted))
                    micro_shots.append(len(shots))
                    tokens += int(batch_tokens)
                    if not acc.sync_gradients:
                        continue
                    self.step += 1
                    losses.append(sum(micro_losses) / len(micro_losses))
                    seconds = time.perf_counter() - start
                    rate = tokens / seconds
                    if log is not None:
                        log.write(json.dumps({"step": self.step, "epoch": epoch,
                                              "loss": round(losses[-1], 5),
                                              "lr": self.scheduler.get_last_lr()[0],
                                              "shots": (micro_shots[0] if len(micro_shots) == 1
                                                        else micro_shots),
                                              "tokens_per_s": round(rate, 1),
                                              "seconds": round(seconds, 2),
                                              "dtype": self.dtype_name}) + "\n")
                        log.flush()
                    micro_losses, micro_shots, tokens = [], [], 0
                    bar.set_postfix(loss=f"{losses[-1]:.3f}", tok_s=f"{rate:.0f}", refresh=False)
                    bar.update()
                    if self.step % cfg.checkpoint_every == 0:
                        self.save_checkpoint()
                    if self.step >= self.total_steps:
                        break
        finally:
            bar.close()
            if log is not None:
                log.close()
        return losses

    def _open_log(self):
        """``train_log.jsonl`` to append to, after ending the half line a killed session
        may have left, so that no later step's line is glued to it."""
        path = self.out / "train_log.jsonl"
        log = open(path, "a")
        if log.tell() and path.read_bytes()[-1:] != b"\n":
            log.write("\n")
        return log

    def _shots(self, micro, epoch: int, index: int):
        """The batch's worked examples, drawn by its position (see ``shot_rng``)."""
        return batch_shots(self.train_records, micro, self.config.data.shots,
                           shot_rng(self.config.seed, epoch, index))

    # -- checkpoints ----------------------------------------------------------------
    def save_checkpoint(self) -> Path:
        """Adapter, optimizer, scheduler and RNG state at the current step; then the
        oldest checkpoints beyond ``keep_checkpoints`` go (only once the new one is whole,
        so an interruption never leaves the run without one)."""
        folder = checkpoint_folder(self.out, self.step)
        if folder.joinpath("step.json").is_file():
            # Already whole (the last step is also a checkpoint step): writing it again in
            # place would leave a torn checkpoint that still reads as whole if killed.
            return folder
        self.accelerator.save_state(str(folder))
        if self.accelerator.is_main_process:
            folder.joinpath("step.json").write_text(json.dumps({"step": self.step}))
            for old in whole_checkpoints(self.out)[:-self.config.keep_checkpoints]:
                shutil.rmtree(old)
        self.accelerator.wait_for_everyone()
        return folder

    def _load_checkpoint(self) -> None:
        found = whole_checkpoints(self.out)
        if not found:
            # Killed before its first checkpoint: nothing to go on from, so it starts over
            # (its log's steps are taken again).
            warnings.warn(f"{self.out} has no checkpoint yet: training starts again from "
                          "step 0", stacklevel=2)
            if self.accelerator.is_main_process:
                self.out.joinpath("train_log.jsonl").unlink(missing_ok=True)
            return
        self.accelerator.load_state(str(found[-1]))
        self.step = json.loads(found[-1].joinpath("step.json").read_text())["step"]

    # -- the end --------------------------------------------------------------------
    def save_adapter(self) -> Path:
        folder = self.out / "adapter"
        self.accelerator.unwrap_model(self.model).save_pretrained(folder)
        self.tokenizer.save_pretrained(folder)
        return folder

    def heldout_check(self) -> dict:
        """Validity and accuracy of the tuned model on test pairs, through the harness,
        with each prompt layout it trained on (each count of worked examples).

        The top-level ``validity`` and ``accuracy`` are those of the weakest layout. Call
        it last: on a CPU it casts the model to fp32 for good.
        """
        from ara.eval.translate.backends.hf_backend import HFBackend
        from ara.eval.translate.prompt import sample_shots
        from ara.eval.translate.translator import Translator
        from ara.grammars.spot_bridge import judge

        n, form = self.config.eval_pairs, self.config.data.forms[0]
        model = self.accelerator.unwrap_model(self.model).eval()
        if next(model.parameters()).device.type == "cpu":
            # One sentence at a time, fp32 answers sooner than bf16 on a CPU, even with
            # the output layer fed 2-D rows (bench/hf_generation_head.py); the adapter is
            # saved by now, so the cast changes nothing that is kept.
            model = model.float()
        backend = HFBackend.from_objects(model, self.tokenizer, f"lora:{self.out.name}")
        translator = Translator(backend)
        tests = self.split.records("test", form)[:n]
        pool = self.split.records("train", form)
        by_shots = {}
        for k in sorted(set(self.config.data.shots)):
            shots = sample_shots(pool, k, random.Random(f"{self.config.seed}:heldout:{k}"))
            results = [(r, translator.translate(r.nl, r.aps, shots, constrained=True))
                       for r in tqdm(tests, desc=f"held-out check, {k} shots", leave=False)]
            verdicts = [judge(r.stl, res.stl, timeout_s=10)["equivalent"] for r, res in results]
            by_shots[str(k)] = {
                "validity": sum(res.valid for _, res in results) / max(1, len(results)),
                "accuracy": sum(bool(v) for v in verdicts) / max(1, len(results))}
        report = {"pairs": len(tests), "form": form, "by_shots": by_shots,
                  "validity": min(v["validity"] for v in by_shots.values()),
                  "accuracy": min(v["accuracy"] for v in by_shots.values())}
        self.out.joinpath("heldout.json").write_text(json.dumps(report, indent=2) + "\n")
        return report


def run_training(config: TrainConfig, resume: bool = False) -> dict:
    """Train, save the adapter, run the held-out check; returns a summary."""
    with exclusive(Path(config.out)):
        return _run_training(config, resume)


def _run_training(config: TrainConfig, resume: bool) -> dict:
    recipe = LoRAFinetuneRecipe(config, resume)
    recipe.setup()
    recipe.train()
    recipe.save_checkpoint()
    summary = {"steps": recipe.step, **log_summary(recipe.out / "train_log.jsonl")}
    if recipe.accelerator.is_main_process:  # one adapter and one check, whatever the processes
        summary["adapter"] = str(recipe.save_adapter())
        if config.eval_pairs:
            summary["heldout"] = recipe.heldout_check()
    recipe.accelerator.wait_for_everyone()
    return summary


def main(config_path: str, max_steps: int | None = None, resume: bool = False) -> dict:
    """``ara train --config``: one run, or every stage of a staged recipe not yet done."""
    from ara.training.stage_runner import run_recipe
    from ara.training.stages import StagedRecipe, is_staged

    data = read_config(config_path)
    if is_staged(data):
        # A recipe resumes by itself: each rerun goes on where the last one stopped.
        return run_recipe(StagedRecipe.from_dict(data), max_steps)
    config = TrainConfig.from_dict(data)
    if max_steps is not None:
        config = TrainConfig.from_dict({**config.to_dict(), "max_steps": max_steps})
    return run_training(config, resume)


def _check_base_model(model: str) -> None:
    """Refuse a ``base_model`` that is neither a folder here nor a hub id in the local
    Hugging Face cache, before anything loads (nothing is downloaded)."""
    from huggingface_hub import try_to_load_from_cache

    if Path(model).is_dir():
        return
    try:
        cached = isinstance(try_to_load_from_cache(model, "config.json"), str)
    except ValueError:  # not a hub id at all (a path that does not exist, say)
        cached = False
    if not cached:
        raise ConfigError(f"base_model {model!r} is no folder here, nor a hub id in the local "
                          "cache: set it to your local copy of the model (nothing is "
                          "downloaded)")
