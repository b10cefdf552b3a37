"""Natural language to STL: the translator, and the paper's F/P/C ablation judged by Spot.

* :mod:`ara.eval.translate`: the product, what ``ara translate`` runs.
* :mod:`ara.eval.harness`, :mod:`ara.eval.ablation`: resumable evaluation runs over it.
* :mod:`ara.eval.metrics`, :mod:`ara.eval.report`, :mod:`ara.eval.run_diff`: their
  figures, tables and comparisons.
"""
