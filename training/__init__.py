"""LoRA fine-tuning of Gemma 3 (transformers + peft + accelerate), on a CPU for the
embedded 270M or on GPUs, then merge and GGUF export.

* :mod:`ara.training.recipe`: the training run, top to bottom.
* :mod:`ara.training.config`: the YAML config, checked on load.
* :mod:`ara.training.export`: merge, convert with llama.cpp, quantize, parity check.
"""
