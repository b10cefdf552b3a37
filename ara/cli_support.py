"""What every subcommand shares: turning toolkit errors into exit code 2 and output."""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import typer

from ara.errors import AraError, ConfigError

#: Exit code for a check's "no" (``ara stl equiv`` of formulas that differ).
EXIT_NO = 1
#: Exit code for bad input (invalid formula, unknown option value, missing data).
EXIT_BAD_INPUT = 2
#: Exit code for a check that ran out of time (the answer is unknown, not no).
EXIT_UNDECIDED = 3


@contextmanager
def user_errors() -> Iterator[None]:
    """Print a toolkit error, or a file that cannot be read or written, as ``error: ...`` on
    stderr and exit with code 2 (3 on timeout)."""
    try:
        yield
    except TimeoutError as err:
        typer.echo(f"undecided: {err}", err=True)
        raise typer.Exit(EXIT_UNDECIDED) from None
    except AraError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except OSError as err:
        if not err.filename:  # not a path: a failure of the machine, with its traceback
            raise
        # A path that cannot be read or written: most often one the user gave.
        where = err.filename + (f" -> {err.filename2}" if err.filename2 else "")
        typer.echo(f"error: {err.strerror or err}: {where}", err=True)
        raise typer.Exit(EXIT_BAD_INPUT) from None


def emit(value: Any, as_json: bool, human: Callable[[Any], str] | None = None) -> None:
    """Print ``value`` as one JSON object, or as the text ``human`` makes of it."""
    if as_json:
        sys.stdout.write(json.dumps(value, sort_keys=True) + "\n")
    else:
        typer.echo(human(value) if human else value)


def split_list(text: str) -> tuple[str, ...]:
    """``"a, b,c"`` -> ``("a", "b", "c")``."""
    return tuple(item.strip() for item in text.split(",") if item.strip())


def int_list(text: str, option: str) -> tuple[int, ...]:
    """``"0,5"`` -> ``(0, 5)``, or a ConfigError naming the option."""
    try:
        return tuple(int(k) for k in split_list(text))
    except ValueError:
        raise ConfigError(f"{option} takes comma-separated whole numbers, e.g. 0,5; "
                          f"got {text!r}") from None
