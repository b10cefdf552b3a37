"""The NL2TL data: vendored raw files, normalization, seeded splits, versions."""

from ara.data.normalize import NORMALIZER_VERSION, Record, RejectedRow
from ara.data.store import (
    SPLITS,
    DataVersionWarning,
    PreparedSplit,
    build_split,
    default_root,
    load_or_prepare,
    load_split,
    prepare,
    registered_version,
    to_hf,
)

__all__ = [
    "NORMALIZER_VERSION",
    "SPLITS",
    "DataVersionWarning",
    "PreparedSplit",
    "Record",
    "RejectedRow",
    "build_split",
    "default_root",
    "load_or_prepare",
    "load_split",
    "prepare",
    "registered_version",
    "to_hf",
]
