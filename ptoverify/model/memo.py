"""One memo mechanism, keyed on configuration objects.

A computation that depends only on a configuration (a frozen dataclass such
as :class:`ptoverify.config.Config` or :class:`ptoverify.config.Plant`) and on
a few plain options is remembered per distinct key: the report, the gates and
the laws that ask for the same zone share one construction.  Keys are checked:
frozen dataclasses, str, int, float, bool, None, and tuples of these.  Arrays,
bytes, dicts and other mutable or unhashable objects are refused (TypeError),
so no memo is keyed on a buffer's bytes or on an object's identity.

:func:`memo` wraps :func:`functools.lru_cache` (public) with that check and
registers the wrapped function, so :func:`clear_memos` empties every memo.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from typing import Any, TypeVar

__all__ = ["memo", "clear_memos", "check_key"]

F = TypeVar("F", bound=Callable[..., Any])

_PLAIN = (str, int, float, bool, type(None))
_REGISTRY: list[Callable[..., Any]] = []


def check_key(value: object) -> None:
    """Raise TypeError unless ``value`` may be part of a memo key.

    Parameters
    ----------
    value : object
        A dataclass instance hashed by value (frozen), str, int, float, bool,
        None, or a tuple of these (nested).

    Raises
    ------
    TypeError
        For anything else (arrays, bytes, lists, dicts, dataclasses that are
        unhashable or hashed by identity).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> check_key((paper_config(), "strict", 200))
    >>> check_key(b"bytes")
    Traceback (most recent call last):
    ...
    TypeError: memo key of type bytes: use a frozen dataclass, str, int, float, bool or None
    """
    if isinstance(value, _PLAIN):
        return
    if isinstance(value, tuple):
        for v in value:
            check_key(v)
        return
    hash_fn = getattr(type(value), "__hash__", None)
    if (
        dataclasses.is_dataclass(value)
        and not isinstance(value, type)
        and hash_fn is not None  # a mutable dataclass with eq has no hash
        and hash_fn is not object.__hash__  # hashed by value (frozen), not by identity
    ):
        return
    raise TypeError(
        f"memo key of type {type(value).__name__}: use a frozen dataclass, str, int, "
        "float, bool or None"
    )


def memo(maxsize: int | None = 64) -> Callable[[F], F]:
    """Return a decorator that memoizes a function on checked keys.

    Parameters
    ----------
    maxsize : int or None
        Entries kept per function (least recently used dropped first) [-];
        None: no limit (for a few objects built once per option set).

    Returns
    -------
    callable
        The decorator; the decorated function has ``cache_clear()`` and
        ``cache_info()`` as :func:`functools.lru_cache` gives them.

    Examples
    --------
    >>> @memo(maxsize=4)
    ... def double(x: float) -> float:
    ...     return 2.0 * x
    >>> double(1.5), double.cache_info().misses
    (3.0, 1)
    """

    def decorate(fn: F) -> F:
        cached = functools.lru_cache(maxsize=maxsize)(fn)

        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            check_key(args)
            check_key(tuple(kwargs.values()))
            return cached(*args, **kwargs)

        wrapper.cache_clear = cached.cache_clear  # type: ignore[attr-defined]
        wrapper.cache_info = cached.cache_info  # type: ignore[attr-defined]
        _REGISTRY.append(wrapper)
        return wrapper  # type: ignore[return-value]

    return decorate


def clear_memos() -> None:
    """Empty every memo made with :func:`memo` (for tests that perturb internals).

    Examples
    --------
    >>> clear_memos()
    """
    for fn in _REGISTRY:
        fn.cache_clear()
