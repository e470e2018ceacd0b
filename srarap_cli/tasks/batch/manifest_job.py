"""One job of a batch manifest, typed: its files, its gates and its settings as layers."""
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

from ...solver.settings import overlay
from ..comparison import Expect


@dataclass(frozen=True)
class ManifestJob:
    """A manifest's job as :func:`.manifest.load_manifest` reads it.

    Attributes
    ----------
    name : str, unique in its manifest
    mesh, handles : str, absolute paths
    output : str, relative to the batch's output folder
    expect : Expect or None, the job's gates and golden mesh
    golden_root : str, the manifest's folder: the only place its goldens may be written
    layers : tuple of mappings, setting values by name: the manifest's ``defaults``, the
        job's own ``settings``, then the command line's options; :attr:`settings` lays them
        one over the other
    goldens : str, what to do with goldens (see :data:`..comparison.goldens.GOLDEN_MODES`)

    Examples
    --------
    >>> job = ManifestJob("a", "/m.obj", "/h.yaml", "a.obj", layers=({"allow": "units"},))
    >>> job.over({"allow": "needles", "tol": 1e-8}).settings
    {'allow': ('units', 'needles'), 'tol': 1e-08}
    """

    name: str
    mesh: str
    handles: str
    output: str
    expect: Expect | None = None
    golden_root: str | None = None
    layers: tuple[Mapping[str, Any], ...] = ()
    goldens: str = "check"

    @property
    def settings(self) -> dict[str, Any]:
        """The job's settings: its layers laid over each other, later ones winning and
        ``allow``'s codes adding up (:func:`~srarap_cli.solver.settings.overlay`), as
        ``srarap deform`` lays a handle file's under its options."""
        return overlay(*self.layers)

    def over(self, layer: Mapping[str, Any]) -> "ManifestJob":
        """This job with ``layer`` (the command line's settings) laid over its own."""
        return replace(self, layers=(*self.layers, dict(layer)))
