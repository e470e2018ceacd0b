"""A batch manifest: its jobs, with absolute paths and merged settings, and the check that no
output lands on what a job reads (see :mod:`.batch` for the format)."""
import os

from ...io.documents import load_document
from ...io.handles import referenced_files
from ...io.mesh.formats import extensions, suffix_of
from ...runtime.errors import InputError, excerpt, unknown_key
from ...runtime.paths import leads_out, refuse_overwriting_inputs
from ...solver.settings import parse_mapping
from ..comparison import parse_expect, record_path, refuse_leading_out
from .manifest_job import ManifestJob

TOP_KEYS = ("jobs", "defaults")
JOB_KEYS = ("name", "mesh", "handles", "output", "settings", "expect")
#: the files a batch writes beside its jobs' in the output folder
SUMMARIES = ("summary.csv", "summary.json")


def load_manifest(path: str) -> list[ManifestJob]:
    """Jobs of a manifest, with absolute paths, their settings' layers (the manifest's
    ``defaults`` under the job's ``settings``) and their gates."""
    doc = load_document(path, "json" if path.lower().endswith(".json") else "yaml")
    if isinstance(doc, dict):
        _known(f"{path}", doc, TOP_KEYS, "the manifest")
    if not isinstance(doc, dict) or not isinstance(doc.get("jobs"), list) or not doc["jobs"]:
        raise InputError(f"{path}: a manifest needs a non-empty 'jobs' list")
    base = os.path.dirname(os.path.abspath(path))
    defaults = _settings(path, "defaults", doc.get("defaults", {}))
    jobs: list[ManifestJob] = []
    names: set[str] = set()
    outputs: set[str] = set()
    for k, job in enumerate(doc["jobs"]):
        where = f"{path}: job {k}"
        if isinstance(job, dict):
            _known(where, job, JOB_KEYS, "the job")
        if not isinstance(job, dict) or not {"mesh", "handles", "output"} <= set(job):
            raise InputError(f"{where}: needs mesh, handles and output")
        output = _output_name(where, job["output"])
        if output in outputs:
            raise InputError(f"{where}: output {output!r} is also another job's output")
        _refuse_nesting(where, output, outputs)
        outputs.add(output)
        name = str(job.get("name", os.path.splitext(output)[0]))
        if name in names:
            raise InputError(f"{where}: job name {name!r} used twice")
        names.add(name)
        expect = job.get("expect")
        if expect is not None:
            expect = _expect(where, base, expect)
        own = _settings(where, "settings", job.get("settings", {}))
        jobs.append(ManifestJob(name, os.path.join(base, str(job["mesh"])),
                                os.path.join(base, str(job["handles"])), output, expect,
                                golden_root=base, layers=(defaults, own)))
    return jobs


def _expect(where, base, spec):
    """A job's ``expect`` as an Expect, its golden relative to the manifest's folder."""
    golden = spec.get("golden") if isinstance(spec, dict) else None
    return parse_expect(spec, lambda message: InputError(f"{where}: {message}"),
                        None if golden is None else os.path.join(base, str(golden)))


def _known(where, mapping, allowed, what):
    """Refuse a key ``what`` does not take, with the nearest one it does as a hint."""
    unknown = sorted(set(map(str, mapping)) - set(allowed))
    if unknown:
        raise InputError(f"{where}: {unknown_key(unknown[0], allowed, what)}")


def _output_name(where, value):
    """A job's output as a relative path inside the output folder, with a mesh extension."""
    if not isinstance(value, str) or not value:
        raise InputError(f"{where}: output must be a file name")
    norm = os.path.normpath(value)
    if os.path.isabs(value) or norm == ".." or norm.startswith(".." + os.sep):
        raise InputError(f"{where}: output {excerpt(value)!r} must stay inside the output "
                         "folder (-o): no absolute path, no '..'")
    if suffix_of(norm) not in extensions():
        raise InputError(f"{where}: output {excerpt(value)!r} needs one of the extensions "
                         f"{', '.join(extensions())}")
    return norm


def _refuse_nesting(where, output, outputs):
    """An output that would be a folder of another's (``x.obj`` and ``x.obj/y.obj``): one of
    the two jobs could never write."""
    parts = output.split(os.sep)
    for other in outputs:
        theirs = other.split(os.sep)
        short, long_ = sorted((parts, theirs), key=len)
        if len(short) < len(long_) and long_[:len(short)] == short:
            raise InputError(f"{where}: output {output!r} and another job's {other!r}: one "
                             "would be a folder holding the other")


def check_outputs(jobs: list[ManifestJob],
                  out_dir: str, manifest: str) -> None:
    """Refuse a run whose outputs (or their sidecars) would land on any job's input or the
    manifest: a batch must never overwrite what it reads."""
    inputs = [("manifest", manifest)]
    for job in jobs:
        inputs += _inputs(job)
        if job.expect:
            inputs.append((f"golden mesh of job {job.name!r}", job.expect.golden))
    _stay_inside(jobs, out_dir)
    outputs = [os.path.join(out_dir, name) for job in jobs
               for name in (job.output, job.output + ".srarap.json")]
    outputs += [os.path.join(out_dir, name) for name in SUMMARIES]
    refuse_overwriting_inputs(outputs, inputs)


def check_goldens(jobs: list[ManifestJob], manifest: str) -> None:
    """Before ``--update-goldens`` runs anything: refuse a golden (or its record) that would
    be written outside its manifest's folder (symbolic links followed), onto any input of the
    run, or that two jobs would both write."""
    inputs = [("manifest", manifest)]
    for job in jobs:
        inputs += _inputs(job)
    owners: dict[str, str] = {}
    for job in jobs:
        if not job.expect:
            continue
        golden = job.expect.golden
        root = job.golden_root or os.path.dirname(os.path.abspath(manifest))
        refuse_leading_out(golden, root, f"job {job.name!r}: golden ")
        other = owners.setdefault(os.path.realpath(golden), job.name)
        if other != job.name:
            raise InputError(f"job {job.name!r}: golden {golden} is also job {other!r}'s: "
                             "--update-goldens would write it twice")
        refuse_overwriting_inputs([golden, record_path(golden)], inputs)


def _inputs(job):
    """What ``job`` reads, each with its words: its mesh, its handle file and the files that
    names."""
    return [(f"mesh of job {job.name!r}", job.mesh),
            (f"handle file of job {job.name!r}", job.handles),
            *((f"file named by job {job.name!r}'s handles", path)
              for path in referenced_files(job.handles))]


def _stay_inside(jobs, out_dir):
    """Refuse, before any job runs, an output, a record or a summary that a symbolic link
    inside ``out_dir`` would carry outside it (the names were checked as text when the
    manifest was read; the writes check again when they happen)."""
    for job in jobs:
        for name in (job.output, job.output + ".srarap.json"):
            target = leads_out(os.path.join(out_dir, name), out_dir)
            if target is not None:
                raise InputError(f"job {job.name!r}: {name!r} leads out of the output "
                                 f"folder {out_dir} (through a symbolic link, to {target})")
    for name in SUMMARIES:
        target = leads_out(os.path.join(out_dir, name), out_dir)
        if target is not None:
            raise InputError(f"{os.path.join(out_dir, name)}: leads out of the output folder "
                             f"{out_dir} (through a symbolic link, to {target})")


def _settings(where, key, spec):
    return parse_mapping(spec, key, lambda message: InputError(f"{where}: {message}"))
