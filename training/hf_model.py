"""The embedded Gemma 3 270M as a local Hugging Face folder, converted once.

transformers reads the GGUF (dequantized to float32, ``Gemma3ForCausalLM``), but
slowly (its 262k-token tokenizer most of all), and a model loaded from GGUF refuses
``save_pretrained``. So the conversion copies its state
dict into a fresh ``Gemma3ForCausalLM(config)``, saves that with the tokenizer, and
writes ``ara_model.json`` (source GGUF hash, versions) beside them. Later calls find
the folder and return at once. Nothing is downloaded. Also the model's tokenizer, read
once a process, and a base model with a saved LoRA adapter on it (a warm start).
"""

from __future__ import annotations

import json
import shutil
from functools import lru_cache
from pathlib import Path

from ara import __version__
from ara.errors import AraError, ConfigError
from ara.provenance import cache_root, sha256_file

MANIFEST = "ara_model.json"
#: Bumped when the folder's layout changes, so older conversions are redone.
FORMAT = 2


class ModelPrepError(AraError, RuntimeError):
    """The base model could not be converted or found."""


def training_dtype(precision: str, device):
    """The torch dtype the frozen base model computes in on ``device`` (see
    ``TrainConfig.precision``)."""
    import torch

    if precision == "auto":
        if device.type == "cuda":
            native = torch.cuda.is_bf16_supported(including_emulation=False)
        else:
            # AMX and AVX512-BF16 multiply bf16 natively (bench/training_step_cost.py);
            # without either bf16 is converted and loses to fp32.
            native = device.type == "cpu" and any(
                getattr(torch.cpu, probe, lambda: False)()
                for probe in ("_is_amx_tile_supported", "_is_avx512_bf16_supported"))
        precision = "bf16" if native else "fp32"
    return torch.bfloat16 if precision == "bf16" else torch.float32


def forward_in(dtype, model, device):
    """Where the base is bf16, the training forward runs under autocast: the fp32 LoRA
    layers take their bf16 inputs as they are and multiply in bf16 (peft would copy
    each input to fp32 first, which took the gain away on a CPU). Outside it (the
    held-out check's generation) peft's copies stay: the LoRA part in fp32, added back
    in bf16."""
    from contextlib import ExitStack

    import torch
    from peft.helpers import disable_input_dtype_casting

    stack = ExitStack()
    if dtype == torch.bfloat16:
        stack.enter_context(torch.autocast(device.type, dtype=torch.bfloat16))
        stack.enter_context(disable_input_dtype_casting(model))
    return stack


def default_hf_dir() -> Path:
    return cache_root() / "models" / "gemma-3-270m-hf"


def is_prepared(folder: Path, gguf_sha256: str | None = None) -> bool:
    """Whether ``folder`` holds a finished conversion (of that GGUF, if given)."""
    path = folder / MANIFEST
    if not path.is_file() or not (folder / "model.safetensors").is_file():
        return False
    manifest = json.loads(path.read_text())
    if manifest.get("format") != FORMAT:
        return False
    return gguf_sha256 is None or manifest["gguf_sha256"] == gguf_sha256


def prepare_base_model(out: Path | None = None, gguf_path: str | None = None,
                       force: bool = False) -> Path:
    """Convert a GGUF (the embedded Gemma 3 270M by default) into a HF folder.

    Args:
        out: Target folder; :func:`default_hf_dir` by default.
        gguf_path: The GGUF to convert.
        force: Convert again even if ``out`` already holds this conversion.

    Returns:
        The folder, loadable with ``from_pretrained(folder)``.
    """
    from ara.eval.translate.models import default_model_path

    gguf = Path(gguf_path or default_model_path())
    if not gguf.is_file():
        raise ModelPrepError(f"GGUF file not found: {gguf}")
    out = out or default_hf_dir()
    digest = sha256_file(gguf)
    if not force and is_prepared(out, digest):
        return out
    # The folder is replaced whole: only one this function wrote (or none) may be.
    if out.exists() and not (out / MANIFEST).is_file() and any(Path(out).iterdir()):
        raise ModelPrepError(f"{out} is not empty and holds no {MANIFEST}: name a new "
                             "folder for the conversion (it is replaced whole)")

    import transformers
    from transformers import AutoModelForCausalLM, AutoTokenizer

    tokenizer = AutoTokenizer.from_pretrained(str(gguf.parent), gguf_file=gguf.name)
    loaded = AutoModelForCausalLM.from_pretrained(str(gguf.parent), gguf_file=gguf.name)
    # A GGUF-loaded model refuses save_pretrained; a fresh one with its weights does not.
    model = type(loaded)(loaded.config)
    # The weights are plain float32 now; a leftover "quant_method: gguf" would make
    # loaders and llama.cpp's converter look for quantized tensors.
    if hasattr(model.config, "quantization_config"):
        del model.config.quantization_config
    missing, unexpected = model.load_state_dict(loaded.state_dict(), strict=False)
    if unexpected or [k for k in missing if "lm_head" not in k]:
        raise ModelPrepError(f"weights did not fit: missing {missing}, unexpected {unexpected}")
    model.tie_weights()
    staging = out.with_name(out.name + ".partial")
    shutil.rmtree(staging, ignore_errors=True)
    model.save_pretrained(staging)
    tokenizer.save_pretrained(staging)
    (staging / MANIFEST).write_text(json.dumps({
        "format": FORMAT, "gguf": gguf.name, "gguf_sha256": digest,
        "architecture": type(model).__name__,
        "parameters": sum(p.numel() for p in model.parameters()),
        "transformers_version": transformers.__version__, "ara_version": __version__,
    }, indent=2, sort_keys=True) + "\n")
    shutil.rmtree(out, ignore_errors=True)
    staging.rename(out)
    return out


def load_tokenizer(model_dir: str | Path):
    """The tokenizer of a model folder, read once per process while its files are
    unchanged: parsing Gemma's 262k vocabulary takes seconds, and a recipe's stages (and
    the tests' many short runs) read the same one. Callers only read it (encode, pad,
    save a copy beside an adapter)."""
    return _tokenizer(str(model_dir), _stamp(model_dir))


@lru_cache(maxsize=2)
def _tokenizer(model_dir: str, stamp: tuple):
    """``stamp`` keys the cache to the files, so a rewritten folder is read again."""
    from transformers import AutoTokenizer

    return AutoTokenizer.from_pretrained(model_dir, local_files_only=True)


def _stamp(model_dir) -> tuple:
    return tuple(sorted((f.name, f.stat().st_mtime_ns, f.stat().st_size)
                        for f in Path(model_dir).glob("*token*")))


def warm_started(base, folder: str, lora):
    """``base`` with the trainable adapter saved in ``folder``, checked against ``lora``:
    a warm start whose shape differs from the config would record one thing and train
    another. Dropout is no part of the shape: the run trains with the config's."""
    from peft import LoraConfig, PeftModel

    saved = LoraConfig.from_pretrained(folder)
    checks = [("r", saved.r, lora.r), ("alpha", saved.lora_alpha, lora.alpha)]
    # A saved adapter lists the modules "all-linear" resolved to, so only an explicit
    # list in the config can be compared with it.
    if lora.target_modules != "all-linear":
        checks.append(("target_modules", sorted(saved.target_modules),
                       sorted(lora.target_modules)))
    mismatched = {name: (got, want) for name, got, want in checks if got != want}
    if mismatched:
        detail = ", ".join(f"{k}: adapter {g} vs config {w}" for k, (g, w) in mismatched.items())
        raise ConfigError(f"init_adapter {folder} has another LoRA shape ({detail}); "
                          "set lora to the adapter's values")
    saved.lora_dropout = lora.dropout
    return PeftModel.from_pretrained(base, folder, is_trainable=True, config=saved)
