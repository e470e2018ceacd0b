"""What decides a run's outputs, hashed: one fingerprint for a batch job's record and an
animation's resume state, so that a rerun is up to date exactly when nothing that changes
its files changed.

It hashes the inputs' bytes, the resolved settings (the defaults, the handle file's
``solver`` section, the manifest's and the command line's layers: writing a default out
changes nothing) less those whose table entry says they decide nothing
(``Setting.decides``: the thread count, ``strict``, ``allow``), the output options that
change what is written, and srarap's version.
"""
import hashlib
import json
from collections.abc import Iterable, Mapping
from importlib import metadata
from typing import Any

from ..solver.settings import SETTINGS, Settings

#: settings that do not change what a run writes (see :class:`~..solver.settings.Setting`):
#: a rerun that changes only them is up to date (a batch judges its recorded warnings under
#: the rerun's strictness instead)
NOT_DECIDING = tuple(s.name for s in SETTINGS if not s.decides)


def deciding(settings: Settings) -> dict[str, Any]:
    """The resolved ``settings`` less those that do not change the outputs.

    Examples
    --------
    >>> from srarap_cli.solver.settings import resolve
    >>> "threads" in deciding(resolve({"threads": 4})), deciding(resolve())["tol"]
    (False, 1e-06)
    """
    return {k: v for k, v in settings.as_dict().items() if k not in NOT_DECIDING}


def fingerprint(inputs: Iterable[bytes], settings: Settings,
                outputs: Mapping[str, Any]) -> str:
    """SHA-256 (hex) of each input's bytes, the deciding settings, the output options
    ``outputs`` (JSON-serializable: the output's name, its format and what it holds) and
    srarap's version.

    Examples
    --------
    >>> from srarap_cli.solver.settings import resolve
    >>> a = fingerprint([b"mesh"], resolve({"threads": 1}), {"output": "a.obj"})
    >>> a == fingerprint([b"mesh"], resolve({"tol": 1e-6}), {"output": "a.obj"})
    True
    >>> a == fingerprint([b"mesh"], resolve(), {"output": "a.obj", "distortion": True})
    False
    """
    h = hashlib.sha256()
    for data in inputs:
        h.update(hashlib.sha256(data).digest())
    h.update(json.dumps([deciding(settings), dict(outputs), metadata.version("srarap-cli")],
                        sort_keys=True, default=str).encode())
    return h.hexdigest()
