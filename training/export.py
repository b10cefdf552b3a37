"""From a LoRA run to GGUF files that llama.cpp serves, with a parity check.

1. Merge the adapter into the *unquantized* base (never into a quantized model), and
   save the merged model as a HF folder.
2. Convert the merged folder to an f16 (or f32) GGUF with llama.cpp's own
   ``convert_hf_to_gguf.py``, taken from the llama-cpp-python source package of the
   version we run, so the converter and the runtime agree.
3. Quantize with llama.cpp (``llama_model_quantize``) to q8_0, q4_k_m, ...
4. Optionally convert the adapter alone to a GGUF LoRA (``convert_lora_to_gguf.py``),
   a few MB that llama.cpp applies on top of the base GGUF.
5. Write ``export.json``: hashes, base, run.

:func:`peft_from_gguf` goes the other way: a GGUF LoRA back to the PEFT folder a warm
start reads, so a shipped adapter is one file.

``parity`` then checks that the exported GGUF, through llama-cpp-python, and the merged
HF model give the same greedy formula on test pairs.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tarfile
from importlib.metadata import version
from pathlib import Path

from ara.errors import AraError
from ara.provenance import cache_root, sha256_file

#: Test pairs the greedy parity check of an export compares by default (0: none).
PARITY_PAIRS = 20
#: llama.cpp quantization types by name (``llama_ftype`` values).
QUANT_TYPES = {"f32": 0, "f16": 1, "q8_0": 7, "q4_k_m": 15, "q5_k_m": 17, "q6_k": 18}


class ExportError(AraError, RuntimeError):
    """An export step that failed, with what it ran."""


def converter_dir() -> Path:
    """llama.cpp's conversion scripts and gguf-py, extracted once from the sdist.

    ``make setup`` calls this; the sdist comes from PyPI (the only network we use).
    """
    llama_version = version("llama-cpp-python")
    folder = cache_root() / "tools" / f"llama.cpp-{llama_version}"
    if (folder / "convert_hf_to_gguf.py").is_file():
        return folder
    download = cache_root() / "tools" / "sdist"
    download.mkdir(parents=True, exist_ok=True)
    fetch = [sys.executable, "-m", "pip", "download", "-q", "--no-deps", "--no-binary", ":all:",
             "-d", str(download), f"llama-cpp-python=={llama_version}"]
    found = list(download.glob(f"llama_cpp_python-{llama_version}.tar.gz"))
    if not found and subprocess.run(fetch).returncode != 0:
        raise ExportError(
            f"could not fetch llama.cpp's converter (the llama-cpp-python {llama_version} "
            f"sdist) from the package index: run `{' '.join(fetch[2:])}` where the index "
            "is reachable, or `make setup`, which does it once")
    (sdist,) = found or download.glob(f"llama_cpp_python-{llama_version}.tar.gz")
    staging = folder.with_name(folder.name + ".partial")
    prefix = f"llama_cpp_python-{llama_version}/vendor/llama.cpp/"
    wanted = ("convert_hf_to_gguf.py", "convert_lora_to_gguf.py", "conversion/", "gguf-py/")
    with tarfile.open(sdist) as tar:
        members = [m for m in tar.getmembers()
                   if m.name.startswith(prefix) and m.name[len(prefix):].startswith(wanted)]
        for m in members:
            m.name = m.name[len(prefix):]
        tar.extractall(staging, members=members, filter="data")
    staging.rename(folder)
    return folder


def _run_converter(script: str, args: list[str]) -> None:
    tools = converter_dir()
    env = {**os.environ, "PYTHONPATH": str(tools / "gguf-py")}
    done = subprocess.run([sys.executable, str(tools / script), *args], env=env,
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise ExportError(f"{script} {' '.join(args)} failed:\n{done.stderr[-2000:]}")


def merge_adapter(base_dir: str, adapter_dir: str, out: Path) -> Path:
    """The base with the LoRA merged in, saved as a HF folder (float32)."""
    import torch
    from peft import PeftModel
    from transformers import AutoModelForCausalLM, AutoTokenizer

    base = AutoModelForCausalLM.from_pretrained(base_dir, local_files_only=True,
                                                dtype=torch.float32)
    merged = PeftModel.from_pretrained(base, adapter_dir).merge_and_unload()
    merged.save_pretrained(out)
    # A training run saves the tokenizer beside its adapter; a soup of committed
    # adapters has none, and the base's is the same one
    has_own = Path(adapter_dir, "tokenizer.json").is_file()
    AutoTokenizer.from_pretrained(adapter_dir if has_own else base_dir).save_pretrained(out)
    return out


def to_gguf(hf_dir: Path, outfile: Path, outtype: str = "f16") -> Path:
    """Convert a HF folder to one GGUF file (``outtype`` f32, f16 or bf16)."""
    _run_converter("convert_hf_to_gguf.py", [str(hf_dir), "--outfile", str(outfile),
                                             "--outtype", outtype])
    return outfile


def quantize(src: Path, dst: Path, quant: str) -> Path:
    """Quantize a GGUF with llama.cpp."""
    import llama_cpp

    if quant not in QUANT_TYPES:
        raise ExportError(f"unknown quantization {quant!r}; choose from {sorted(QUANT_TYPES)}")
    params = llama_cpp.llama_model_quantize_default_params()
    params.ftype = QUANT_TYPES[quant]
    status = llama_cpp.llama_model_quantize(str(src).encode(), str(dst).encode(), params)
    if status != 0:
        raise ExportError(f"llama_model_quantize({src} -> {quant}) returned {status}")
    return dst


def lora_to_gguf(base_dir: str, adapter_dir: str, outfile: Path, outtype: str = "f16") -> Path:
    """The adapter alone as a GGUF LoRA for llama.cpp (f16 halves the file that ships)."""
    _run_converter("convert_lora_to_gguf.py", [adapter_dir, "--base", base_dir,
                                               "--outfile", str(outfile), "--outtype", outtype])
    return outfile


#: The Gemma 3 modules an ``all-linear`` LoRA adapts, as ``model.layers.N.`` names them.
GEMMA3_LINEAR = ("self_attn.q_proj", "self_attn.k_proj", "self_attn.v_proj",
                 "self_attn.o_proj", "mlp.gate_proj", "mlp.up_proj", "mlp.down_proj")


#: The version of :func:`peft_from_gguf`'s output, part of the cache's folder names: a
#: change to what it writes must not meet a folder an earlier release converted.
PEFT_FROM_GGUF_VERSION = 1


def peft_from_gguf(lora: Path, out: Path) -> Path:
    """A Gemma 3 GGUF LoRA (:func:`lora_to_gguf`) as a PEFT adapter folder in ``out``: its
    own weights, in their own precision, under PEFT's names, with its rank, alpha and
    adapted modules. What a warm start from a shipped file reads (``init_adapter: finetuned``).

    Raises:
        ExportError: If ``lora`` is not an f16 or f32 LoRA of Gemma 3's linear layers,
            with A and B of one rank for each.
    """
    import re

    import gguf
    import numpy as np
    from peft import LoraConfig
    from safetensors.numpy import save_file

    reader = gguf.GGUFReader(lora)
    meta = {k: f.contents() for k, f in reader.fields.items()
            if k in ("general.architecture", "adapter.type", "adapter.lora.alpha")}
    if (meta.get("general.architecture"), meta.get("adapter.type")) != ("gemma3", "lora"):
        raise ExportError(f"{lora} is not a GGUF LoRA of Gemma 3 ({meta})")
    if "adapter.lora.alpha" not in meta:
        raise ExportError(f"{lora} does not say its LoRA alpha (adapter.lora.alpha)")
    tensors = {t.name: t for t in reader.tensors}
    floats = {gguf.GGMLQuantizationType.F16, gguf.GGMLQuantizationType.F32}
    if odd := sorted(t.name for t in tensors.values() if t.tensor_type not in floats):
        raise ExportError(f"{lora} holds tensors neither f16 nor f32 ({odd[:3]}): export the "
                          "LoRA with --outtype f16 or f32")
    blocks = 1 + max((int(m[1]) for name in tensors if (m := re.match(r"blk\.(\d+)\.", name))),
                     default=-1)
    names = gguf.get_tensor_name_map(gguf.MODEL_ARCH.GEMMA3, blocks)
    weights, adapted, ranks = {}, set(), set()
    for block in range(blocks):
        for module in GEMMA3_LINEAR:
            hf = f"model.layers.{block}.{module}"
            layer = names.get_name(f"{hf}.weight", try_suffixes=(".weight",))
            a, b = tensors.pop(f"{layer}.lora_a", None), tensors.pop(f"{layer}.lora_b", None)
            if a is None and b is None:
                continue
            if a is None or b is None:
                raise ExportError(f"{lora}: {layer} has lora_{'b' if a is None else 'a'} "
                                  "without its other half")
            for part, tensor in (("A", a), ("B", b)):
                # The reader gives each tensor as PEFT lays it out (out x in), row-major.
                weights[f"base_model.model.{hf}.lora_{part}.weight"] = np.array(tensor.data)
            ranks |= {weights[f"base_model.model.{hf}.lora_A.weight"].shape[0],
                      weights[f"base_model.model.{hf}.lora_B.weight"].shape[1]}
            adapted.add(module.rpartition(".")[2])
    if tensors or not weights:
        raise ExportError(f"{lora} has tensors no Gemma 3 linear layer takes: "
                          f"{sorted(tensors)[:3] or 'none at all'}")
    if len(ranks) != 1:
        raise ExportError(f"{lora} mixes LoRA ranks {sorted(ranks)}")
    out.mkdir(parents=True, exist_ok=True)
    LoraConfig(r=ranks.pop(), lora_alpha=float(meta["adapter.lora.alpha"]), lora_dropout=0.0,
               target_modules=sorted(adapted), task_type="CAUSAL_LM").save_pretrained(out)
    save_file(weights, str(out / "adapter_model.safetensors"), metadata={"format": "pt"})
    return out


def shipped_peft(lora: Path) -> Path:
    """:func:`peft_from_gguf` of a shipped GGUF LoRA, converted once into the cache under
    the file's hash (a file shipped later is converted anew). One process converts at a
    time; the others wait for its folder."""
    import fcntl

    root = cache_root() / "peft"
    out = root / f"{lora.stem}-{sha256_file(lora)[:16]}-v{PEFT_FROM_GGUF_VERSION}"
    root.mkdir(parents=True, exist_ok=True)
    with open(root / f"{out.name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (out / "adapter_model.safetensors").is_file():
            partial = out.with_name(out.name + ".partial")  # a kill mid-write leaves no `out`
            shutil.rmtree(partial, ignore_errors=True)
            peft_from_gguf(lora, partial).rename(out)
    return out


def export_run(run_dir: Path, quants: tuple[str, ...] = ("f16",), lora_gguf: bool = False,
               outtype: str = "f16") -> dict:
    """Export a finished training run (``ara train``) into ``run_dir/export``."""

    run = json.loads((run_dir / "run.json").read_text())
    base_dir, adapter = run["base_model"]["path"], str(run_dir / "adapter")
    out = run_dir / "export"
    out.mkdir(exist_ok=True)
    merged = merge_adapter(base_dir, adapter, out / "merged-hf")
    full = to_gguf(merged, out / f"model-{outtype}.gguf", outtype)
    files = {full.name: full}
    for quant in quants:
        if quant != outtype:
            files[f"model-{quant}.gguf"] = quantize(full, out / f"model-{quant}.gguf", quant)
    if lora_gguf:
        files["lora.gguf"] = lora_to_gguf(base_dir, adapter, out / "lora.gguf")
    manifest = {"run": str(run_dir), "base_model": run["base_model"],
                "config": run["config"], "data": run["data"],
                "files": {name: {"sha256": sha256_file(p), "bytes": p.stat().st_size}
                          for name, p in files.items()}}
    (out / "export.json").write_text(json.dumps(manifest, indent=2, sort_keys=True) + "\n")
    return manifest


def parity(gguf: Path, hf_dir: Path, records, lora: Path | None = None,
           constrained: bool = False) -> dict:
    """Greedy answers of the GGUF (llama.cpp) and the HF folder (transformers), compared."""
    from ara.eval.translate.backends.hf_backend import HFBackend
    from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend
    from ara.eval.translate.translator import Translator

    llama = Translator(LlamaCppBackend(str(gguf), lora_path=str(lora) if lora else None))
    hf = Translator(HFBackend(str(hf_dir)))
    pairs = [(llama.translate(r.nl, r.aps, (), constrained=constrained).raw.strip(),
              hf.translate(r.nl, r.aps, (), constrained=constrained).raw.strip())
             for r in records]
    agree = sum(a == b for a, b in pairs)
    return {"pairs": len(pairs), "agree": agree, "agreement": agree / max(1, len(pairs)),
            "disagreements": [p for p in pairs if p[0] != p[1]][:5]}


def export_checked(run_dir: Path, quants: tuple[str, ...] | list[str] = ("f16",),
                   lora_gguf: bool = False, parity_pairs: int = PARITY_PAIRS) -> dict:
    """:func:`export_run`, then the greedy parity of the GGUF and the merged HF model on
    the first ``parity_pairs`` test pairs of the data version the run trained on (0: no
    check); the manifest, with ``parity``, is ``run_dir/export/export.json``."""
    quants = tuple(quants)
    _check_before_work(Path(run_dir), quants, parity_pairs)
    outtype = "f32" if "f32" in quants else "f16"
    manifest = export_run(Path(run_dir), quants, lora_gguf, outtype)
    if parity_pairs:
        from ara.data import load_split

        saved = json.loads((Path(run_dir) / "run.json").read_text())
        config = saved["config"]
        records = load_split(config["data"]["split"], config["data"]["seed"],
                             version=saved["data"]["version"]).records(
            "test", config["data"]["forms"][0])[:parity_pairs]
        export = Path(run_dir) / "export"
        manifest["parity"] = parity(export / f"model-{outtype}.gguf", export / "merged-hf",
                                    records)
        (export / "export.json").write_text(json.dumps(manifest, indent=2) + "\n")
    return manifest


def _check_before_work(run_dir: Path, quants: tuple[str, ...], parity_pairs: int) -> None:
    """What would fail after minutes of merging and converting, refused at once."""
    unknown = [q for q in quants if q not in QUANT_TYPES]
    if unknown or not quants:
        raise ExportError(f"unknown quantization {unknown or quants!r}; choose from "
                          f"{sorted(QUANT_TYPES)}")
    if parity_pairs < 0:
        raise ExportError(f"--parity takes a number of pairs (0: no check), not {parity_pairs}")
    for need in ("run.json", "adapter/adapter_config.json"):
        if not (run_dir / need).is_file():
            raise ExportError(f"{run_dir} has no {need}: name a finished `ara train` run "
                              "folder (one with adapter/)")
