"""``srarap samples``: copy the shipped sample meshes and handle files into a folder."""
import os
from importlib import resources

import click

from ..runtime.commit import commit_files
from ..runtime.errors import OutputError
from .common import guarded, say

#: what is copied: meshes, handle files and a batch manifest, and the goldens it checks against
SUBFOLDERS = ("sample_meshes", "configs", "golden")


@click.command("samples")
@click.argument("folder")
@click.option("--force", is_flag=True, help="Replace files of the same names in FOLDER.")
@click.option("-q", "--quiet", is_flag=True, help="No summary line.")
@guarded
def samples(folder: str, force: bool, quiet: bool) -> None:
    """Copy the sample meshes, handle files and goldens into FOLDER (three subfolders).

    Then, for example: srarap deform FOLDER/sample_meshes/bar.obj FOLDER/configs/bar-twist.yaml
    -o twisted.obj
    """
    if not folder.strip():
        raise click.BadParameter("FOLDER is empty; name a folder, '.' for this one",
                                 param_hint="FOLDER")
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
    if not quiet:
        say(f"srarap samples: wrote {len(files)} files to {folder}")
