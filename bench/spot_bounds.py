"""How long Spot takes to decide equivalence as interval bounds grow.

Spot unrolls F[a..b] into nested X, so its automata grow with the bounds. This script
times ``equivalent`` on formula shapes taken from NL2TL's timed data, each check in a
subprocess with a time limit, and prints one table; SPOT_MAX_BOUND in
``grammars/spot_bridge.py`` is chosen from it.

    .venv/bin/python bench/spot_bounds.py [--limit-s 60] [--bounds 25,50,100,150,200]
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import platform
import time

SHAPES = {
    "F[b/2,b] & G[0,b] vs U[b/3,b]": ("F[{h},{b}](a) & G[0,{b}](b)", "a U[{t},{b}] b"),
    "G(a -> F[b/2,b] G c)": ("G(a -> F[{h},{b}](G(c)))", "G(a -> F[{h},{b}](G(c))) & F[0,{b}](b)"),
    "G[b/4,b/2](!a) U[b/2,b] b": ("G[{q},{h}](!a) U[{h},{b}] b",
                                  "G[{q},{h}](!a) U[{h},{b}] (b & c)"),
    "F[b/2,b](a -> b) -> c": ("F[{h},{b}](a -> b) -> c", "F[{q},{b}](a -> b) -> c"),
}


def _check(a: str, b: str, out) -> None:
    import ara.grammars.spot_bridge as sb
    from ara.grammars import parse

    sb.SPOT_MAX_BOUND = 10**9
    start = time.perf_counter()
    sb.equivalent(parse(a), parse(b))
    out.put(time.perf_counter() - start)


def timed(a: str, b: str, limit_s: float) -> float | None:
    out: mp.Queue = mp.Queue()
    proc = mp.Process(target=_check, args=(a, b, out))
    proc.start()
    proc.join(limit_s)
    if proc.is_alive():
        proc.kill()
        return None
    return out.get()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--limit-s", type=float, default=60.0, help="time limit per check")
    ap.add_argument("--bounds", default="25,50,100,150,200", help="comma-separated bounds b")
    args = ap.parse_args()
    bounds = [int(x) for x in args.bounds.split(",")]
    print(f"# Spot equivalence time (s) by bound b; '>{args.limit_s:g}' = killed at the limit")
    print(f"# machine: {platform.machine()}, {mp.cpu_count()} cores, "
          f"python {platform.python_version()}")
    print("| shape | " + " | ".join(f"b={b}" for b in bounds) + " |")
    print("|---|" + "---|" * len(bounds))
    for name, (a, b_) in SHAPES.items():
        cells = []
        for b in bounds:
            fill = dict(b=b, h=b // 2, t=b // 3, q=b // 4)
            secs = timed(a.format(**fill), b_.format(**fill), args.limit_s)
            cells.append(f">{args.limit_s:g}" if secs is None else f"{secs:.2f}")
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
