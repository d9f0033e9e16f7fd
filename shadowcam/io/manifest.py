"""Capture descriptions (manifests): load, validate, resolve files and times, checksums.

A manifest (``data_manifest/<name>.yaml``, or the renderer's ``capture.json``)
says where a dataset's files are, their sha256 checksums, how frame times are
known, and provenance. Its structure is fixed by
``shadowcam/io/schemas/manifest.schema.yaml`` (see ``docs/contracts.md``).

:func:`load_manifest` returns the document as a dict with these additions:

* ``manifest_path`` -- absolute path of the manifest file;
* ``root`` -- made absolute (relative roots resolve against the manifest's folder);
* ``sweeps[name]["paths"]`` -- natural-sorted absolute paths of the sweep's files;
* ``sweeps[name]["times_s"]`` -- frame times in seconds (float list, one per file);
* ``reference_paths`` -- absolute paths of the reference frame(s) (empty if none);
* ``camera_array["paths"]`` -- absolute paths of a camera array's crossing images, row-major;
* ``files`` -- group -> list of paths relative to root of every referenced file;
  groups are the sweep names, ``reference``, ``timing`` (sidecar), ``ground_truth``,
  ``calibration_plane`` (mask) and ``sky_mask`` (outdoor mask image).

Offers
------
SCHEMA_PATH : location of the JSON schema (YAML).
natural_key : sort key that orders "frame2" before "frame10".
load_manifest : read, validate and resolve a manifest.
manifest_files : referenced files (relative -> absolute path), optionally by group.
verify_checksums : check the sha256 of referenced files against the manifest.
checksums_for : compute the checksums block for a manifest being written.
format_checksums : the ``checksums:`` YAML block for a checksum mapping.
frame_times : frame times in seconds of a list of files from a timing spec.
"""

import datetime as _dt
import glob
import json
import logging
import math
import os
import re
from pathlib import Path

import jsonschema
import yaml

from shadowcam.io.provenance import file_sha256

log = logging.getLogger(__name__)

#: JSON schema of a manifest (YAML), shipped inside the package
SCHEMA_PATH = Path(__file__).resolve().parent / "schemas" / "manifest.schema.yaml"

#: libyaml's safe loader where PyYAML was built with it (a manifest lists every frame's checksum)
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

_FIX_CHECKSUMS = "run `shadowcam checksum --manifest {m}` and paste its output into the manifest"


def natural_key(text):
    """Return a sort key splitting digit runs into integers ("f2" < "f10")."""
    return [int(part) if part.isdigit() else part.lower() for part in re.split(r"(\d+)", str(text))]


def _read_document(path):
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"manifest file {path} does not exist")
    text = path.read_text()
    try:
        doc = json.loads(text) if path.suffix.lower() == ".json" else yaml.load(text, Loader=_YAML_LOADER)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise ValueError(f"manifest {path} is not valid {'JSON' if path.suffix == '.json' else 'YAML'}: {exc}") from None
    if not isinstance(doc, dict):
        raise ValueError(f"manifest {path} must hold a mapping (key: value pairs) at top level")
    return doc


def _schema():
    if not SCHEMA_PATH.is_file():
        raise ValueError(f"manifest schema {SCHEMA_PATH} not found: reinstall shadowcam (pip install .)")
    return yaml.safe_load(SCHEMA_PATH.read_text())


def _validate(doc, path):
    validator = jsonschema.Draft202012Validator(_schema())
    errors = sorted(validator.iter_errors(doc), key=lambda e: list(map(str, e.absolute_path)))
    if not errors:
        return
    lines = []
    for error in errors:
        where = ".".join(str(p) for p in error.absolute_path) or "(top level)"
        best = jsonschema.exceptions.best_match([error])
        if error.context:  # oneOf / anyOf: show the most relevant sub-error
            best = jsonschema.exceptions.best_match(error.context)
            where = ".".join(str(p) for p in best.absolute_path) or where
        lines.append(f"  key {where}: {best.message}")
    raise ValueError(
        f"manifest {path} does not match the schema {SCHEMA_PATH.name}:\n" + "\n".join(lines)
        + "\nFix or remove these keys (structure: docs/contracts.md)."
    )


def _rel(root, path):
    return Path(os.path.relpath(path, root)).as_posix()


def _expand(root, pattern, *, what, manifest_path):
    if os.path.isabs(pattern):
        raise ValueError(f"manifest {manifest_path}: {what} {pattern!r} must be relative to root {root}")
    matches = [p for p in glob.glob(os.path.join(root, pattern), recursive=True) if os.path.isfile(p)]
    if not matches:
        raise ValueError(
            f"manifest {manifest_path}: {what} {pattern!r} matches no file under root {root}; "
            "check the root and the pattern"
        )
    return sorted((Path(p).resolve() for p in matches), key=lambda p: natural_key(_rel(root, p)))


def _existing(root, name, *, what, manifest_path):
    path = (Path(root) / name).resolve()
    if not path.is_file():
        raise ValueError(f"manifest {manifest_path}: {what} file {path} does not exist (key {what})")
    return path


def _crossing_paths(root, block, *, manifest_path):
    """The crossing images of a camera array, row-major (a {row}/{col} pattern or a glob)."""
    pattern = block["crossings"]
    if "{row" not in pattern and "{col" not in pattern:
        return _expand(root, pattern, what="camera_array.crossings", manifest_path=manifest_path)
    try:
        names = [pattern.format(row=i, col=j) for i in range(block["rows"]) for j in range(block["cols"])]
    except (KeyError, IndexError, ValueError) as exc:
        raise ValueError(f"manifest {manifest_path}: key 'camera_array.crossings' pattern {pattern!r} "
                         f"cannot be filled ({exc!r}); use the fields {{row}} and {{col}} only, e.g. "
                         "'crossings/r{row}_c{col}.png'") from None
    return [_existing(root, name, what="camera_array.crossings", manifest_path=manifest_path)
            for name in names]


def _epoch_seconds(iso_text):
    return _dt.datetime.fromisoformat(iso_text).replace(tzinfo=_dt.timezone.utc).timestamp()


def _seconds(value):
    return format(value, ".10g")


def _check_time_order(paths, times, *, root, source):
    """Raise ValueError naming the first two files whose times do not increase in file order."""
    for k in range(1, len(times)):
        if times[k] > times[k - 1]:
            continue
        a, b = _rel(root, paths[k - 1]), _rel(root, paths[k])
        if times[k] == times[k - 1]:
            problem = f"frame {b} ({_seconds(times[k])} s) has the same time as {a}"
        else:
            problem = (f"frame {b} ({_seconds(times[k])} s) comes after {a} ({_seconds(times[k - 1])} s) "
                       "in file-name order but is earlier")
        raise ValueError(
            f"{problem} (timing source {source}); frame times must increase in file-name order: "
            "check the timing source, and rename or remove the files so that name order is time order"
        )


#: longest interval between two frames of an outdoor time-lapse accepted by default (s): in an
#: hour the sun moves 15 deg, the shadow crosses the view unseen, and a longer pause is
#: usually another session (the next day) whose shadows start over
MAX_FRAME_GAP_S = 3600.0


def _check_sessions(paths, times, *, root, max_gap_s):
    """Raise ValueError naming the frames around intervals longer than `max_gap_s`."""
    gaps = [k for k in range(1, len(times)) if times[k] - times[k - 1] > max_gap_s]
    if not gaps:
        return
    shown = "; ".join(f"{_rel(root, paths[k - 1])} -> {_rel(root, paths[k])} "
                      f"({(times[k] - times[k - 1]) / 3600.0:.2f} h)" for k in gaps[:3])
    raise ValueError(
        f"{len(gaps)} interval(s) between frames longer than max_frame_gap_s {max_gap_s:g} s: {shown}"
        f"{' and more' if len(gaps) > 3 else ''}; the sequence looks like separate sessions whose "
        f"shadows start over: split it into one dataset per session at "
        f"{_rel(root, paths[gaps[0]])}, or set max_frame_gap_s in the manifest above the longest "
        "interval if it is one session"
    )


def frame_times(paths, timing, *, root, sweep, sidecar=None):
    """Return frame times in seconds for the files of one sweep, checked to increase.

    Frames are ordered by file name; times that do not increase in that order
    (out of order or duplicated) are an error, not sorted: which file is frame
    ``k`` stays what the names say, and the message names the two files, their
    times and the timing source.

    Parameters
    ----------
    paths : sequence of Path
        The sweep's files in frame order.
    timing : mapping
        The manifest's ``timing`` entry (``source``: rate | filename | metadata |
        sidecar | auto; auto takes the first of metadata, filename, sidecar
        that gives a time for every file, see :mod:`shadowcam.io.frame_times`).
    root : Path
        Dataset root (sidecar keys may be paths relative to it).
    sweep : str
        Sweep name (used by sidecar files keyed by sweep, and in messages).
    sidecar : object, optional
        Parsed sidecar JSON value under ``timing["key"]`` (source sidecar only).

    Returns
    -------
    list of float
        Seconds; for ``rate`` ``start_s + k / rate_hz``; for ``filename`` the
        ``time_s`` group, or the ``index`` group / ``rate_hz`` (default 1);
        for ``metadata`` seconds since the sweep's first frame (EXIF
        DateTimeOriginal + SubsecTimeOriginal); for ``sidecar`` the listed values.

    Raises
    ------
    ValueError
        If a source gives no time for a file, or the times do not increase
        strictly in file order (``auto`` then tries its next source).
    """
    if timing["source"] == "auto":
        return _auto_times(paths, timing, root=root, sweep=sweep, sidecar=sidecar)
    times = _source_times(paths, timing, root=root, sweep=sweep, sidecar=sidecar)
    _check_time_order(paths, times, root=root, source=timing["source"])
    return times


def _auto_times(paths, timing, *, root, sweep, sidecar):
    from shadowcam.io.frame_times import auto_candidates

    problems = []
    for candidate in auto_candidates(timing):
        try:
            times = frame_times(paths, candidate, root=root, sweep=sweep, sidecar=sidecar)
        except ValueError as exc:
            problems.append(f"{candidate['source']}: {exc}")
            continue
        log.info("sweep %s: frame times from %s (timing source auto)", sweep, candidate["source"])
        return times
    raise ValueError("timing.source auto found no source with increasing times for every file ("
                     + "; ".join(problems) + "); add timing.regex or timing.file/key")


def _source_times(paths, timing, *, root, sweep, sidecar):
    """Frame times of one concrete timing source (see :func:`frame_times`), unchecked."""
    source = timing["source"]
    if source == "rate":
        start, rate = float(timing.get("start_s", 0.0)), float(timing["rate_hz"])
        return [start + k / rate for k in range(len(paths))]
    if source == "filename":
        regex = re.compile(timing["regex"])
        if not {"time_s", "index"} & set(regex.groupindex):
            raise ValueError(f"timing.regex {timing['regex']!r} needs a named group (?P<index>...) or (?P<time_s>...)")
        times = []
        for path in paths:
            match = regex.search(Path(path).name)
            if match is None:
                raise ValueError(f"file name {Path(path).name} ({path}) does not match timing.regex {timing['regex']!r}")
            if "time_s" in regex.groupindex:
                times.append(float(match.group("time_s")))
            else:
                times.append(float(match.group("index")) / float(timing.get("rate_hz", 1.0)))
        return times
    if source == "metadata":
        from shadowcam.io.decode import header_metadata

        stamps = [header_metadata(path)["capture_time"] for path in paths]
        missing = [_rel(root, path) for path, stamp in zip(paths, stamps) if stamp is None]
        if missing:
            raise ValueError(
                f"{len(missing)} of {len(paths)} files have no EXIF DateTimeOriginal ({_shown(missing)}; "
                "timing.source metadata needs it on every file); give the times of all files with timing "
                "source sidecar (timing.file, timing.key) or filename (timing.regex), or rate"
            )
        stamps = [_epoch_seconds(stamp) for stamp in stamps]
        return [s - stamps[0] for s in stamps]
    if source == "sidecar":
        value = sidecar
        if isinstance(value, dict) and sweep in value:
            value = value[sweep]
        if isinstance(value, list):
            if len(value) != len(paths):
                raise ValueError(
                    f"sidecar {timing['file']} key {timing['key']!r}: {len(value)} times for sweep "
                    f"{sweep!r} but it has {len(paths)} files"
                )
            return [float(t) for t in value]
        if isinstance(value, dict):
            times = []
            for path in paths:
                rel, name = _rel(root, path), Path(path).name
                if rel not in value and name not in value:
                    raise ValueError(f"sidecar {timing['file']} key {timing['key']!r} has no time for file {rel}")
                times.append(float(value[rel] if rel in value else value[name]))
            return times
        raise ValueError(
            f"sidecar {timing['file']} key {timing['key']!r} must hold a list of seconds, "
            "or a mapping of file or sweep name to seconds"
        )
    raise ValueError(f"timing.source {source!r} is not one of rate, filename, metadata, sidecar")


def _shown(names, limit=5):
    names = list(names)
    return ", ".join(names[:limit]) + (f" and {len(names) - limit} more" if len(names) > limit else "")


def _numbering_gaps(rels):
    """Gaps in the frame numbers of a sweep's files: a list of (file before, file after, missing numbers).

    The frame number is the last digit run of the path; files whose paths
    differ elsewhere too (another folder, a time in the name) are no numbered
    sequence and have no gaps. The step is the greatest common divisor of the
    number differences, so keeping every other frame is no gap.
    """
    numbered = []
    for rel in rels:
        match = re.search(r"(\d+)(\D*)$", rel)
        if match is None:
            return []
        numbered.append((rel[:match.start()] + "#" + match.group(2), int(match.group(1))))
    if len(numbered) < 3 or len({template for template, _ in numbered}) != 1:
        return []
    steps = [b[1] - a[1] for a, b in zip(numbered, numbered[1:])]
    if min(steps) <= 0:
        return []
    step = math.gcd(*steps)
    return [(rels[k], rels[k + 1], range(numbered[k][1] + step, numbered[k + 1][1], step))
            for k, diff in enumerate(steps) if diff > step]


def _gap_text(before, after, missing):
    numbers = ", ".join(map(str, missing[:3])) + (f" and {len(missing) - 3} more" if len(missing) > 3 else "")
    return f"{before} is followed by {after} (missing: frame number{'s' if len(missing) > 1 else ''} {numbers})"


def _check_contents(manifest, files, root):
    """The checksums block states what the capture contains: compare it with the files found.

    Raises ValueError naming the files when a listed file is missing, a found
    file is not listed, a sweep's files are of several file types, or a
    sweep's frame numbers have a gap. Costs no read of a frame file.
    """
    path = manifest["manifest_path"]
    listed = manifest.get("checksums", {})
    found = {rel for group in files.values() for rel in group}  # the globs saw these files: they exist
    gone = [rel for rel in listed if rel not in found and root is not None and not (Path(root) / rel).is_file()]
    if gone:
        raise ValueError(
            f"manifest {path}: file(s) listed in checksums are missing: {_shown(gone)} (under root {root}); "
            "the checksums block states what the capture contains: restore the file(s), or if they were "
            "removed on purpose " + _FIX_CHECKSUMS.format(m=path)
        )
    unlisted = [rel for group in files.values() for rel in group if rel not in listed]
    if unlisted:
        raise ValueError(
            f"manifest {path}: file(s) not listed in checksums: {_shown(unlisted)}; " + _FIX_CHECKSUMS.format(m=path)
        )
    for name, sweep in manifest["sweeps"].items():
        rels = files[name]
        where = f"manifest {path}, sweep {name!r} (files {sweep['files']!r})"
        suffixes = [os.path.splitext(rel)[1].lower() for rel in rels]
        counts = {s: suffixes.count(s) for s in dict.fromkeys(suffixes)}
        if len(counts) > 1:
            usual = max(counts, key=counts.get)
            odd = [rel for rel, s in zip(rels, suffixes) if s != usual]
            raise ValueError(
                f"{where}: a sweep's files must be of one file type; found "
                + ", ".join(f"{s or '(no suffix)'} ({n})" for s, n in counts.items())
                + f"; odd file(s): {_shown(odd)}. Remove or convert them, or narrow the glob"
            )
        gaps = _numbering_gaps(rels)
        if gaps:
            text = "; ".join(_gap_text(*gap) for gap in gaps[:3])
            raise ValueError(
                f"{where}: gap in the frame numbers: {text}{' and more' if len(gaps) > 3 else ''}; "
                "a missing frame shifts the time of every later frame. Restore the missing file(s), "
                "or if frames were removed on purpose renumber the files without gaps and "
                + _FIX_CHECKSUMS.format(m=path)
            )


def _resolve(path, *, strict):
    """Load + validate; with `strict`, also require checksums and resolve times."""
    path = Path(path).resolve()
    doc = _read_document(path)
    if "sweeps" in doc and "checksums" not in doc:
        if strict:
            raise ValueError(
                f"manifest {path} has sweeps but no checksums block (files not listed in checksums); "
                + _FIX_CHECKSUMS.format(m=path)
            )
        doc["checksums"] = {}  # being written: the block does not exist yet
    _validate(doc, path)
    manifest = dict(doc)
    manifest["manifest_path"] = str(path)
    files = {}
    if "root" in manifest:
        root = (path.parent / manifest["root"]).resolve()
        if not root.is_dir():
            raise ValueError(
                f"manifest {path}: root {manifest['root']!r} -> {root} is not a folder "
                "(relative roots resolve against the manifest file's directory)"
            )
        manifest["root"] = str(root)
    else:
        root = None
    sweeps = {}
    for name, sweep in (manifest.get("sweeps") or {}).items():
        paths = _expand(root, sweep["files"], what=f"sweeps.{name}.files", manifest_path=path)
        sweeps[name] = dict(sweep, paths=[str(p) for p in paths])
        files[name] = [_rel(root, p) for p in paths]
    manifest["sweeps"] = sweeps
    manifest["reference_paths"] = []
    if "reference" in manifest:
        refs = _expand(root, manifest["reference"], what="reference", manifest_path=path)
        manifest["reference_paths"] = [str(p) for p in refs]
        files["reference"] = [_rel(root, p) for p in refs]
    if "camera_array" in manifest:
        crossings = _crossing_paths(root, manifest["camera_array"], manifest_path=path)
        manifest["camera_array"] = dict(manifest["camera_array"], paths=[str(p) for p in crossings])
        files["crossings"] = [_rel(root, p) for p in crossings]
    timing = manifest.get("timing", {})
    if timing.get("source") == "sidecar" or (timing.get("source") == "auto" and "file" in timing):
        files["timing"] = [_rel(root, _existing(root, timing["file"], what="timing.file", manifest_path=path))]
    if "ground_truth" in manifest:
        gt_root = root if root is not None else path.parent
        gt = _existing(gt_root, manifest["ground_truth"]["file"], what="ground_truth.file", manifest_path=path)
        if root is not None:
            files["ground_truth"] = [_rel(root, gt)]
    if "image" in manifest.get("sky_mask", {}):
        sky = _existing(root, manifest["sky_mask"]["image"], what="sky_mask.image", manifest_path=path)
        files["sky_mask"] = [_rel(root, sky)]
    if "mask" in manifest.get("calibration_plane", {}):
        mask = _existing(root, manifest["calibration_plane"]["mask"], what="calibration_plane.mask", manifest_path=path)
        files["calibration_plane"] = [_rel(root, mask)]
    manifest["files"] = files
    if not strict:
        return manifest
    _check_contents(manifest, files, root)
    sidecar = None
    if "timing" in files:
        side_path = Path(root) / files["timing"][0]
        try:
            side_doc = json.loads(side_path.read_text())
        except json.JSONDecodeError as exc:
            raise ValueError(f"timing sidecar {side_path} is not valid JSON: {exc}") from None
        key = timing.get("key", "times_s")
        if not isinstance(side_doc, dict) or key not in side_doc:
            raise ValueError(f"timing sidecar {side_path} has no key {key!r} (timing.key)")
        sidecar = side_doc[key]
    for name, sweep in sweeps.items():
        try:
            sweep["times_s"] = frame_times(
                [Path(p) for p in sweep["paths"]], timing, root=root, sweep=name, sidecar=sidecar
            )
            if manifest.get("kind") == "outdoor":
                _check_sessions(sweep["paths"], sweep["times_s"], root=root,
                                max_gap_s=float(manifest.get("max_frame_gap_s", MAX_FRAME_GAP_S)))
        except ValueError as exc:
            raise ValueError(f"manifest {path}, sweep {name!r}: {exc}") from None
    return manifest


def load_manifest(path):
    """Read, validate and resolve a capture description.

    Parameters
    ----------
    path : str or Path
        YAML (``data_manifest/<name>.yaml``) or JSON (``capture.json``) file.

    Returns
    -------
    dict
        The document plus ``manifest_path``, absolute ``root``,
        ``sweeps[name]["paths"]`` / ``["times_s"]``, ``reference_paths`` and
        ``files`` (see the module docstring). A synthetic manifest (with
        ``synthetic`` and no ``sweeps``) has empty ``sweeps``.

    Raises
    ------
    ValueError
        Naming the manifest, the key and the file when: the document does not
        match the schema (unknown or missing keys, wrong types), the root or a
        referenced file is missing, a glob matches nothing, a referenced file
        is not listed in ``checksums``, or frame times cannot be resolved.
    """
    return _resolve(path, strict=True)


def manifest_files(manifest, names=None):
    """Return referenced files as {path relative to root: absolute path}.

    Parameters
    ----------
    manifest : dict
        From :func:`load_manifest`.
    names : iterable of str, optional
        Groups to include: sweep names, ``reference``, ``timing``,
        ``ground_truth``, ``calibration_plane``. Default: all.

    Returns
    -------
    dict of str to str
    """
    groups = manifest.get("files", {})
    if names is None:
        names = list(groups)
    elif isinstance(names, str):
        names = [names]
    unknown = [n for n in names if n not in groups]
    if unknown:
        raise ValueError(
            f"names {unknown} are not file groups of manifest {manifest.get('manifest_path')}; "
            f"available: {sorted(groups)}"
        )
    return {rel: str(Path(manifest["root"]) / rel) for n in names for rel in groups[n]}


def verify_checksums(manifest, names=None):
    """Check the sha256 of referenced files against the manifest's ``checksums``.

    Parameters
    ----------
    manifest : dict
        From :func:`load_manifest`.
    names : iterable of str, optional
        File groups to check (see :func:`manifest_files`); default: every file.

    Returns
    -------
    dict of str to str
        Path relative to root -> verified sha256 (for provenance attrs).

    Raises
    ------
    ValueError
        On the first file that is missing or whose digest differs, with the
        file name, the expected and the actual digest.
    """
    listed = manifest.get("checksums", {})
    mpath = manifest.get("manifest_path")
    verified = {}
    for rel, path in manifest_files(manifest, names).items():
        if not os.path.isfile(path):
            raise ValueError(f"file {path} listed in manifest {mpath} does not exist")
        if rel not in listed:
            raise ValueError(f"file {path} is not listed in checksums of manifest {mpath}; " + _FIX_CHECKSUMS.format(m=mpath))
        actual = file_sha256(path)
        if actual != listed[rel]:
            raise ValueError(
                f"checksum mismatch for {path} (manifest {mpath}, checksums key {rel!r}): "
                f"expected {listed[rel]}, actual {actual}. The file changed since the manifest was "
                "written; restore it, or if the change is intended " + _FIX_CHECKSUMS.format(m=mpath)
            )
        verified[rel] = actual
    log.info("verified sha256 of %d file(s) of %s", len(verified), mpath)
    return verified


def checksums_for(manifest_path):
    """Compute the sha256 of every file a manifest references.

    The manifest must match the schema, but its ``checksums`` block may be
    missing or stale (this is how it is written in the first place).

    Parameters
    ----------
    manifest_path : str or Path

    Returns
    -------
    dict of str to str
        Path relative to root -> sha256, in natural order.
    """
    manifest = _resolve(manifest_path, strict=False)
    if "root" not in manifest:
        raise ValueError(f"manifest {manifest_path} has no root (a synthetic manifest has no files to checksum)")
    rels = sorted({rel for group in manifest["files"].values() for rel in group}, key=natural_key)
    return {rel: file_sha256(Path(manifest["root"]) / rel) for rel in rels}


def format_checksums(checksums):
    """Return the ``checksums:`` YAML block for a {relative path: sha256} mapping."""
    return yaml.safe_dump({"checksums": dict(checksums)}, sort_keys=False, default_flow_style=False)
