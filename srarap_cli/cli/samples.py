"""``srarap samples``: copy the shipped sample meshes and handle files into a folder."""
import click

from ..tasks.sample_files import copy_samples
from .common import guarded, say


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
    written = copy_samples(folder, force)
    if not quiet:
        say(f"srarap samples: wrote {len(written)} files to {folder}")
