"""Goldens that manage themselves: a golden's record of the run that made it
(``<golden>.srarap.json``: energy, iterations and srarap's version; no seconds, which
would change the file at every update), and the files that
create or replace a golden from an obtained mesh, in the golden's own format, committed
together and only inside the folder the caller allows."""
import json
import os
from collections.abc import Mapping
from importlib import metadata
from typing import Any

from ...io.mesh.formats import by_extension, suffix_of
from ...io.mesh.mesh import Mesh
from ...runtime.commit import commit_files
from ...runtime.errors import InputError
from ...runtime.paths import leads_out
from .gates import Observed

#: what a run does with a golden that is missing or regressed: nothing (``check``), write it
#: and still fail (``update``), write it and pass (``accept``)
GOLDEN_MODES = ("check", "update", "accept")
#: what ``--update-goldens`` did to a job's golden (the summaries' ``golden`` column)
CREATED, UPDATED = "created", "updated"


def record_path(golden: str) -> str:
    """The record kept beside ``golden``."""
    return golden + ".srarap.json"


def read_golden_record(golden: str) -> dict[str, Any] | None:
    """The figures recorded beside ``golden`` (``energy``, ``iterations``), or
    None when there is no readable record: the gates that need one say so."""
    try:
        with open(record_path(golden)) as fh:
            rec = json.load(fh)
    except (OSError, ValueError):
        return None
    if not isinstance(rec, dict):
        return None
    out: dict[str, Any] = {}
    for key, kinds in (("energy", (int, float)), ("iterations", int)):
        value = rec.get(key)
        if isinstance(value, kinds) and not isinstance(value, bool):
            out[key] = value
    return out


def golden_files(golden: str, obtained: Mesh | None, run: Observed,
                 obtained_path: str | None = None) -> list[tuple[str, bytes]]:
    """The files that make ``golden`` the obtained result: the mesh in the golden's format
    (the obtained file's own bytes where both have one extension, else ``obtained``
    encoded) and its record (``run``'s figures, where it has any; a record left from an
    earlier golden is emptied so that no old figure stands beside a new mesh)."""
    fmt = by_extension(golden)
    if fmt is None:
        raise InputError(f"{golden}: a golden needs a mesh extension to be written")
    if obtained_path is not None and suffix_of(obtained_path) == suffix_of(golden):
        with open(obtained_path, "rb") as fh:
            data = fh.read()
    else:
        if obtained is None:
            raise InputError(f"{golden}: nothing obtained to write")
        data = fmt.encode(obtained)[0]
    figures = {k: v for k, v in (("energy", run.energy), ("iterations", run.iterations))
               if v is not None}
    files = [(golden, data)]
    if figures or os.path.exists(record_path(golden)):
        files.append((record_path(golden), _record_bytes(figures)))
    return files


def _record_bytes(figures: Mapping[str, Any]) -> bytes:
    return (json.dumps({**figures, "srarap": metadata.version("srarap-cli")}, indent=2,
                       sort_keys=True) + "\n").encode()


def write_golden(golden: str, obtained: Mesh | None, run: Observed, root: str,
                 obtained_path: str | None = None) -> str:
    """Create or replace ``golden`` (and its record) from the obtained result, all or nothing,
    never outside ``root`` (symbolic links followed, at the moment of writing). Returns
    :data:`CREATED` or :data:`UPDATED`."""
    refuse_leading_out(golden, root)
    action = UPDATED if os.path.exists(golden) else CREATED
    commit_files(golden_files(golden, obtained, run, obtained_path), inside=root)
    return action


def refuse_leading_out(golden: str, root: str, who: str = "") -> None:
    """InputError when ``golden`` or its record would be written outside ``root``."""
    for path in (golden, record_path(golden)):
        target = leads_out(path, root)
        if target is not None:
            raise InputError(f"{who}{path}: a golden is written only inside {root} (it leads to "
                             f"{target}); move the goldens under that folder")
