"""The ``srarap`` command group; each subcommand lives in its own module."""
import click

from .animate import animate
from .batch import batch
from .bench import bench
from .compare import compare
from .deform import deform
from .render import plot, render


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks of failures.")
@click.version_option(package_name="srarap-cli", prog_name="srarap")
def main(debug):
    """Deform triangle meshes as rigidly as possible with smooth rotations (SR-ARAP)."""


main.add_command(deform)
main.add_command(bench)
main.add_command(animate)
main.add_command(compare)
main.add_command(batch)
main.add_command(render)
main.add_command(plot)
