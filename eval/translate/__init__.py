"""The translator: a sentence and its propositions in, one STL formula out, valid by
construction, with what it may have left out said.

The path of one answer, top to bottom:

* :mod:`~ara.eval.translate.answering`: :func:`~ara.eval.translate.answering.answer` and
  the typed :class:`~ara.eval.translate.answering.Answer` that ``ara translate``,
  ``ara.translate``, ``translate-file`` and the harness share.
* :mod:`~ara.eval.translate.repair`: another answer when the greedy one leaves part of
  the request out (samples and one-edit mends, ranked by the model's score).
* :mod:`~ara.eval.translate.checks`: each kind of gap, found on an answer from the
  :class:`~ara.eval.translate.request.Request` (the sentence read once).
* :mod:`~ara.eval.translate.confidence`: the probability note;
  :mod:`~ara.eval.translate.deadline`: the time budget of one answer.
* :mod:`~ara.eval.translate.translator`: the prompt (:mod:`~ara.eval.translate.prompt`)
  and the request's own grammar over a backend (:mod:`~ara.eval.translate.backends`:
  llama.cpp, transformers, HTTP servers);
  :mod:`~ara.eval.translate.models` names them (the shipped adapters in ``eval/models/``).
* :mod:`~ara.eval.translate.request_file`, :mod:`~ara.eval.translate.batch`: files of
  requests (``translate-file``); :mod:`~ara.eval.translate.similar`: worked examples by
  similarity.
"""
