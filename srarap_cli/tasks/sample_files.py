"""The shipped sample meshes, handle files and goldens, copied into a folder (``srarap
samples``), so that a new user's first commands have files to run on."""
import os
from importlib import resources

from ..runtime.commit import commit_files
from ..runtime.errors import OutputError, UsageProblem

#: what is copied: meshes, handle files and a batch manifest, and the goldens it checks against
SUBFOLDERS = ("sample_meshes", "configs", "golden")


def copy_samples(folder: str, force: bool = False) -> list[str]:
    """Copy the samples into ``folder``'s :data:`SUBFOLDERS` (all or none); files of the same
    names are replaced only with ``force``. Returns the paths written."""
    if not folder.strip():
        raise UsageProblem("FOLDER is empty; name a folder, '.' for this one")
    data = resources.files("srarap_cli") / "data"
    files = [(os.path.join(folder, sub, item.name), item.read_bytes())
             for sub in SUBFOLDERS for item in sorted(
                 (data / sub).iterdir(), key=lambda p: p.name)
             if item.is_file() and not item.name.endswith(".py")]
    clash = [path for path, _ in files if os.path.exists(path)]
    if clash and not force:
        raise OutputError(f"{clash[0]}: exists (and {len(clash) - 1} more); --force replaces "
                          "them")
    # checked before any is made: a file in the way leaves no half-made tree behind
    blocked = [os.path.join(folder, sub) for sub in ("", *SUBFOLDERS)
               if os.path.exists(os.path.join(folder, sub))
               and not os.path.isdir(os.path.join(folder, sub))]
    if blocked:
        raise OutputError(f"{blocked[0]}: exists and is not a folder")
    for sub in SUBFOLDERS:
        try:
            os.makedirs(os.path.join(folder, sub), exist_ok=True)
        except OSError as exc:
            raise OutputError(f"{os.path.join(folder, sub)}: cannot create folder: "
                              f"{exc.strerror}") from None
    commit_files(files)
    return [path for path, _ in files]
