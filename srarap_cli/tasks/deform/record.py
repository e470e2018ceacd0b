"""A job's record beside its output (``<output>.srarap.json``): the fingerprint of everything
that decides the output and how the job ended, so that a rerun of an unchanged job reports
that result again without solving."""
import json
from collections.abc import Sequence
from typing import Any

from ...io.handles import referenced_files
from ...io.input_files import read_input_bytes
from ...runtime.errors import InputError
from ...solver.stop import StopReason

#: what a record keeps of a job's result
RECORDED = ("status", "iterations", "energy", "stop", "warnings", "seconds")


def sidecar_path(output: str) -> str:
    """The record of the job writing ``output``."""
    return output + ".srarap.json"


def input_bytes(mesh: str, handles: str) -> list[bytes]:
    """The bytes of the mesh, the handle file and every file it names (a missing one: its
    name, marked), what a job's fingerprint hashes of its inputs."""
    out = []
    for path in (mesh, handles, *referenced_files(handles)):
        try:
            out.append(read_input_bytes(path))
        except InputError:
            out.append(b"missing:" + path.encode("utf-8", "surrogateescape"))
    return out


def read_record(sidecar: str, key: str) -> dict[str, Any] | None:
    """What the record at ``sidecar`` says of the job with fingerprint ``key``; None when
    there is none, it is unreadable, of other inputs, or older than status records."""
    try:
        with open(sidecar) as fh:
            rec = json.load(fh)
    except (OSError, ValueError):
        return None
    if not isinstance(rec, dict) or rec.get("fingerprint") != key or not _well_formed(rec):
        return None
    return {k: rec.get(k) for k in RECORDED} | {"warnings": list(rec.get("warnings") or [])}


#: what a record's status and stop can say (what :func:`record_bytes` writes)
STATUSES = ("ok", "not-converged")
STOPS = frozenset(reason.value for reason in StopReason) | {""}


def _well_formed(rec: dict[str, Any]) -> bool:
    """Whether every field of a record has the type and values srarap writes: one that does
    not (a hand-edited or foreign file with the job's fingerprint) is no record, and the job
    runs again."""
    def number(value, kinds):
        return value is None or (isinstance(value, kinds) and not isinstance(value, bool))

    warnings = rec.get("warnings", [])
    return (rec.get("status") in STATUSES and rec.get("stop", "") in STOPS
            and number(rec.get("iterations"), int) and number(rec.get("energy"), (int, float))
            and number(rec.get("seconds"), (int, float))
            and isinstance(warnings, list) and all(isinstance(w, str) for w in warnings))


def record_bytes(key: str, status: str, iterations: int | None, energy: float | None,
                 stop: str, warnings: Sequence[str], seconds: float | None = None) -> bytes:
    """The record's file content (``seconds``: the solve's, for a seconds gate on a rerun)."""
    return json.dumps({"fingerprint": key, "iterations": iterations, "energy": energy,
                       "status": status, "stop": stop, "warnings": list(warnings),
                       "seconds": seconds}).encode()
