"""Objects whose methods read or change a state held by the Rust core: safe to share
between threads, and picklable.

Threads: each object holds one lock, and every method that touches the core state takes
it (:func:`serialized`), so calls from several threads run one after another, each on the
state the previous one left. The core releases the GIL while it computes; a thread that
waits for the lock waits without the GIL. A call rejected with an ``InputError`` or
``TypeError`` is rejected before the state changes, so the object is as it was.

Pickle and ``copy.deepcopy``: the core objects save their whole state as exact bytes
(every float bit for bit, random streams included), so a copy made mid-record continues
exactly like the original. The copy is taken under the lock, so it is never a state half
way through another thread's call.
"""

from __future__ import annotations

import copy
import functools
import threading


class Stateful:
    """Base of the stateful objects of atomnav (see the module docstring)."""

    def __new__(cls, *args, **kwargs):
        self = super().__new__(cls)
        # set here, not in __init__: pickle and deepcopy build objects without __init__
        self._lock = threading.RLock()
        return self

    def __getstate__(self) -> dict:
        with self._lock:
            state = {k: v for k, v in self.__dict__.items() if k != "_lock"}
            # the core objects' bytes are taken now, under the lock, not when pickle
            # reaches them later
            return {k: copy.deepcopy(v) if type(v).__module__ == "atomnav._core" else v for k, v in state.items()}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)


def serialized(method):
    """``method`` run while holding its object's lock (methods and property getters of a
    :class:`Stateful` that touch the core state)."""

    @functools.wraps(method)
    def locked(self, *args, **kwargs):
        with self._lock:
            return method(self, *args, **kwargs)

    return locked
