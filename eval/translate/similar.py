"""Worked examples chosen by similarity: the pool's pairs that say most nearly what the
request says, to show in its prompt.

What carries an instruction's logic is its wording around the things it names ("then",
"never", "until", "within N", "whenever", "in any order"), not the things themselves: so
each sentence is compared with the words of its propositions masked and its numbers
made one token (:func:`logic_words`). Sentences are TF-IDF vectors of those words and
their bigrams, compared by cosine similarity through an inverted index: a query reads
only the postings of its own terms, so it stays fast over the whole training mixture.
An index is built once per pool and kept by the pool's content hash,
in this process and on disk (``~/.cache/ara/similar``).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import pickle
import re
from collections import Counter, defaultdict
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import numpy as np

from ara.data.mixture import sentence_key
from ara.data.normalize import Record
from ara.provenance import cache_root

#: How worked examples are chosen: drawn at random (with a seed), or by similarity.
EXAMPLES_BY = ("random", "similar")
#: How a proposition's words and a number read in the compared text.
MASK, NUMBER = "<p>", "<n>"
#: Changes to how sentences are compared; part of the cache key.
INDEX_VERSION = 2
_TOKEN = re.compile(r"[a-z][a-z0-9]*(?:_[a-z0-9]+)*|\d+")


def logic_words(nl: str, aps: Sequence[str]) -> list[str]:
    """The words of ``nl`` that say how its propositions combine: a proposition's name or
    any word of it becomes one mask (a run of them one mask), a number ``<n>``.

    >>> logic_words("Go to the dock, then wait 5 steps at the gate", ["go_to_dock", "at_gate"])
    ['<p>', 'the', '<p>', 'then', 'wait', '<n>', 'steps', '<p>', 'the', '<p>']
    """
    names = {ap.lower() for ap in aps}
    parts = {part for name in names for part in name.split("_") if not part.isdigit()}
    words: list[str] = []
    for token in _TOKEN.findall(nl.lower()):
        word = NUMBER if token.isdigit() else MASK if token in names or token in parts else token
        if not (word == MASK and words and words[-1] == MASK):
            words.append(word)
    return words


def _terms(nl: str, aps: Sequence[str]) -> Counter:
    words = logic_words(nl, aps)
    return Counter(words + [f"{a} {b}" for a, b in zip(words, words[1:], strict=False)])


class SimilarExamples:
    """An index of ``pool`` answering "which pairs are most like this request".

    Args:
        pool: The pairs to choose from (training records, or a user's own).
    """

    def __init__(self, pool: Sequence[Record]) -> None:
        self.pool = tuple(pool)
        self.keys: dict[str, list[int]] = defaultdict(list)
        for i, r in enumerate(self.pool):
            self.keys[sentence_key(r.nl)].append(i)
        self.keys = dict(self.keys)
        counts = [_terms(r.nl, r.aps) for r in self.pool]
        frequency = Counter(term for c in counts for term in c)
        n = len(self.pool)
        self.idf = {t: math.log((1 + n) / (1 + f)) + 1.0 for t, f in frequency.items()}
        postings: dict[str, list[tuple[int, float]]] = defaultdict(list)
        norms = np.zeros(n, dtype=np.float64)
        for i, c in enumerate(counts):
            for term, tf in c.items():
                weight = (1 + math.log(tf)) * self.idf[term]
                postings[term].append((i, weight))
                norms[i] += weight * weight
        self.norms = np.sqrt(norms) + 1e-12
        self.postings = {t: (np.array([i for i, _ in p], dtype=np.int32),
                             np.array([w for _, w in p], dtype=np.float64))
                         for t, p in postings.items()}

    def scores(self, nl: str, aps: Sequence[str]) -> np.ndarray:
        """Cosine similarity of the request to every pair of the pool."""
        total = np.zeros(len(self.pool), dtype=np.float64)
        for term, tf in _terms(nl, aps).items():
            if term in self.postings:
                docs, weights = self.postings[term]
                total[docs] += (1 + math.log(tf)) * self.idf[term] * weights
        return total / self.norms

    def nearest(self, nl: str, aps: Sequence[str], k: int,
                other_sentences: bool = False) -> list[Record]:
        """The ``k`` pairs most like the request, least similar first, so that the most
        similar stands right above the request in the prompt; ties go to the earlier
        pair of the pool, so the choice is the same on every run.

        Args:
            other_sentences: Never choose a pair that says the request's own sentence
                (up to case, spacing and a full stop): when measuring, a test sentence
                that is also a training pair would otherwise be shown its answer.
        """
        if k <= 0:
            return []
        if k > len(self.pool):
            raise ValueError(f"asked for {k} examples from a pool of {len(self.pool)} pairs")
        scores = self.scores(nl, aps)
        if other_sentences:
            same = self.keys.get(sentence_key(nl), ())
            scores[list(same)] = -np.inf
        order = np.lexsort((np.arange(len(scores)), -scores))[:k]
        return [self.pool[i] for i in reversed(order)]


def pool_hash(pool: Sequence[Record]) -> str:
    """A content hash of the pairs a pool holds, in order."""
    digest = hashlib.sha256(f"similar-v{INDEX_VERSION}\n".encode())
    for r in pool:
        digest.update(json.dumps([r.nl, r.stl, list(r.aps)]).encode() + b"\n")
    return digest.hexdigest()[:16]


def cache_dir() -> Path:
    return cache_root() / "similar"


def index_for(pool: Sequence[Record]) -> SimilarExamples:
    """The index of ``pool``, built once per content and kept on disk."""
    return _index(pool_hash(pool), tuple(pool))


@lru_cache(maxsize=8)
def _index(key: str, pool: tuple[Record, ...]) -> SimilarExamples:
    path = cache_dir() / f"{key}.pkl"
    if path.is_file():
        try:
            with path.open("rb") as f:
                index = pickle.load(f)
            if isinstance(index, SimilarExamples) and len(index.pool) == len(pool):
                return index
        except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError):
            pass  # a cache from another version (its classes moved) or a torn write
    index = SimilarExamples(pool)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_suffix(f".{os.getpid()}.tmp")
    with partial.open("wb") as f:
        pickle.dump(index, f, protocol=pickle.HIGHEST_PROTOCOL)
    partial.replace(path)  # atomic: a reader never sees half a file
    return index
