"""The KV cache of a transformers forward call, on either side of its rename.

transformers 5.24 renamed ``past_key_values`` to ``cache``, both as the forward's keyword
and as the output's field; the old keyword warns until 5.40 and then goes. The toolkit's
two direct uses of the cache (prefix reuse at inference, the shared prompt prefix in
training) pass it through here, so they run on any transformers 5 release.
"""

from __future__ import annotations

from functools import cache
from typing import Any


@cache
def cache_field() -> str:
    """The name transformers uses for the cache: ``"cache"`` from 5.24 on."""
    from transformers.modeling_outputs import CausalLMOutputWithPast

    fields = CausalLMOutputWithPast.__dataclass_fields__
    return "cache" if "cache" in fields else "past_key_values"


def with_cache(kv_cache: Any) -> dict[str, Any]:
    """Keyword arguments that hand ``kv_cache`` to a forward call."""
    return {cache_field(): kv_cache}


def cache_of(output: Any) -> Any:
    """The cache a forward call returned."""
    return getattr(output, cache_field())
