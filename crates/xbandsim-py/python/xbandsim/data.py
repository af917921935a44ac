"""``RadarDataset``: a generated dataset as (image, target) pairs for training detectors.

It reads a dataset folder made by ``xbandsim dataset`` or ``xbandsim.dataset.generate``
(sample folders or WebDataset tar shards), or renders samples on the fly from a dataset spec.
Items follow torchvision's detection convention::

    image   float32 (C, H, W) in [0, 1]  (C = 1 for ppi_gray.png, 3 for ppi.png)
    target  {"boxes": (N, 4) float32 x0 y0 x1 y1 in pixels, "labels": (N,) int64 category ids,
             "masks": (N, H, W) uint8, "area": (N,) float32, "iscrowd": (N,) int64,
             "track_ids": (N,) int64, "artefacts": (N,) bool,
             "image_id": int, "sample": int, "frame": int}

``artefacts`` marks the labels of artefacts (a dataset made with ``[dataset]
artefact_labels``: sidelobe, second-trace, indirect and multiple echoes, interference, racons,
SARTs, each its own category): echoes where there is no target, which have no track; their
``track_ids`` are -1 (COCO gives null). A dataset with land (``[coast]``) has one ``land``
label per frame that shows land: a region (``iscrowd`` 1, as torchvision's detection
references skip in training), track -1.

``image_id`` is the id annotations.json gives the same image (sample index x frames per
sample + frame + 1), so predictions score against the dataset's own COCO file. A dataset
folder that is not finished is read as it is, with an ``IncompleteDatasetWarning`` saying
what is missing and how to finish it.

NumPy arrays without torch; torch tensors when torch is installed (or ``tensors=True``), so
that ``torch.utils.data.DataLoader(ds, collate_fn=lambda b: tuple(zip(*b)))`` works. The
labels are the dataset's own COCO annotations (docs/formats.md, "Dataset labels"): an object
gets a box only where it can be seen; the masks decode the COCO RLE of each target's own
returns.
"""

import json
import os
import tarfile
import warnings
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _args, _xbandsim
from .errors import ArgumentTypeError, IncompleteDatasetWarning, XbandsimError

PathLike = Union[str, "os.PathLike[str]"]


class _Files:
    """A sample's files by relative name, read on demand."""

    def __init__(self, read: Callable[[str], bytes], names: List[str]) -> None:
        self._read = read
        self.names = names

    def __getitem__(self, name: str) -> bytes:
        return self._read(name)


def _folder_sample(folder: str) -> _Files:
    names = []
    for base, _, files in os.walk(folder):
        for f in files:
            names.append(os.path.relpath(os.path.join(base, f), folder).replace(os.sep, "/"))

    def read(name: str) -> bytes:
        with open(os.path.join(folder, name), "rb") as fh:
            return fh.read()

    return _Files(read, sorted(names))


def _warn_if_unfinished(folder: str, found: int) -> None:
    """Warns (IncompleteDatasetWarning) when the dataset in ``folder`` lacks samples that its
    dataset.json counts, or its index files (README.md, the dataset card, is written last by
    the assembly; annotations.json before it): a run stopped part-way, shard runs not all
    done, or runs with ``assemble=False`` (``--no-assemble``) whose assembly is still to come."""
    try:
        record = _xbandsim.read_record(folder)
    except XbandsimError:
        return  # not a dataset this version wrote: nothing to compare with
    count, seed, per = record["count"], record["seed"] or 0, record["shard_samples"]
    missing = max(0, count - found)
    absent = [
        f for f in ("annotations.json", _xbandsim.CARD_FILE)
        if not os.path.isfile(os.path.join(folder, f))
    ]
    if not missing and not absent:
        return
    what = []
    if missing:
        what.append(f"{missing} of its {count} samples are missing")
    if absent:
        what.append(f"its index files are not written ({', '.join(absent)} absent)")
    command = f"xbandsim dataset SPEC --out {folder} --count {count} --seed {seed}"
    command += record["cli_args"]
    call = f"xbandsim.dataset.generate(SPEC, {folder!r}, {count}, {seed}"
    if per is not None:
        call += f", shard_samples={per}"
    warnings.warn(
        f"{folder}: unfinished dataset: {' and '.join(what)}; {found} samples are read. "
        f"Finish it by running the same command again, which makes only what is missing and "
        f"then writes the index files: `{command}` or {call}) with the spec it was made from",
        IncompleteDatasetWarning,
        stacklevel=3,
    )


class RadarDataset:
    """Samples of an xbandsim dataset as ``(image, target)`` pairs (see the module doc).

    ``source`` is a dataset folder (``samples/`` or ``shards/``) or a dataset spec ``.toml``
    (then ``count`` samples are rendered on the fly with ``seed``, the bytes a generated
    dataset would hold). ``image`` picks ``"gray"`` (ppi_gray.png) or ``"colour"`` (ppi.png),
    whichever the dataset stored; ``masks=False`` skips decoding the masks; ``transforms``
    is called as ``transforms(image, target)``. Sequences (``dataset.frames > 1``) give one
    item per frame.
    """

    def __init__(
        self,
        source: PathLike,
        *,
        count: Optional[int] = None,
        seed: int = 0,
        image: str = "gray",
        masks: bool = True,
        tensors: Optional[bool] = None,
        transforms: Optional[Callable[[Any, Dict[str, Any]], Tuple[Any, Dict[str, Any]]]] = None,
    ) -> None:
        image = _args.choice("image", image, ("gray", "colour"))
        self.image_file = "ppi_gray.png" if image == "gray" else "ppi.png"
        self.masks = _args.flag("masks", masks)
        if transforms is not None and not callable(transforms):
            raise _args.error(
                "transforms", transforms, "must be callable (image, target) or None",
                "wrong type", ArgumentTypeError,
            )
        self.transforms = transforms
        count = _args.optional(_args.whole, "count", count, 1, _args.U64_MAX)
        seed = _args.seed("seed", seed)
        tensors = _args.optional(_args.flag, "tensors", tensors)
        if tensors is None:
            try:
                import torch  # noqa: F401

                tensors = True
            except ImportError:
                tensors = False
        elif tensors:
            try:
                import torch  # noqa: F401
            except ImportError as e:
                raise ImportError(
                    "tensors=True needs torch: pip install './crates/xbandsim-py[torch]' "
                    "(or leave tensors unset for NumPy arrays)"
                ) from e
        self.tensors = tensors
        source = _args.path("source", source)
        self._spec: Optional[str] = None
        self._samples: List[Tuple[int, Callable[[], _Files]]] = []
        if os.path.isfile(source) and source.endswith(".toml"):
            if count is None:
                raise _args.error(
                    "count", count, "a dataset spec needs count (1 or more samples to render)",
                    "missing", ArgumentTypeError,
                )
            self._spec, self._seed = source, seed
            self._samples = [(i, self._render_closure(i)) for i in range(count)]
        elif os.path.isdir(os.path.join(source, "samples")):
            self._samples = self._scan_folders(source)
            _warn_if_unfinished(source, len(self._samples))
        elif os.path.isdir(os.path.join(source, "shards")):
            self._samples = self._scan_shards(os.path.join(source, "shards"))
            _warn_if_unfinished(source, len(self._samples))
        else:
            raise FileNotFoundError(
                f"{source}: neither a dataset folder (with samples/ or shards/) nor a dataset spec .toml"
            )
        if count is not None and self._spec is None:
            self._samples = self._samples[:count]
        # One item per (sample, frame): the frame folders are found in the first sample.
        self._frames = self._frame_prefixes(self._samples[0][1]()) if self._samples else [""]

    def _render_closure(self, index: int) -> Callable[[], _Files]:
        def load() -> _Files:
            # A sequence's frames are items in a row: the sample last rendered is kept, so
            # that its frames do not render the whole sequence again each.
            cached = getattr(self, "_last_rendered", None)
            if cached is not None and cached[0] == index:
                return cached[1]
            rendered = dict(_xbandsim.render_sample(self._spec, self._seed, index))
            files = _Files(rendered.__getitem__, sorted(rendered))
            self._last_rendered = (index, files)  # one assignment: safe between threads
            return files

        return load

    @staticmethod
    def _scan_folders(source: str) -> List[Tuple[int, Callable[[], _Files]]]:
        # The sample folders where the generator puts them (samples/<group>/<index>).
        out = []
        for i in _xbandsim.sample_indices(source):
            folder = os.path.join(source, _xbandsim.sample_dir(i))
            out.append((i, (lambda f=folder: _folder_sample(f))))
        return out

    @staticmethod
    def _scan_shards(root: str) -> List[Tuple[int, Callable[[], _Files]]]:
        # Index every member's byte range once; items read their bytes with one seek each.
        members: Dict[int, Dict[str, Tuple[str, int, int]]] = {}
        shards = sorted(
            (t, f) for f in os.listdir(root)
            if (t := _xbandsim.parse_shard_file_name(f)) is not None
        )
        for _, shard in shards:
            path = os.path.join(root, shard)
            with tarfile.open(path) as tar:
                for m in tar.getmembers():
                    # A sequence's frame folder is joined to the file by a dot in a tar
                    # (000000042.frame_0003.ppi_gray.png): its (sample, file) from Rust.
                    hit = _xbandsim.parse_member_name(m.name) if m.isfile() else None
                    if hit is not None:
                        index, name = hit
                        members.setdefault(index, {})[name] = (
                            path,
                            m.offset_data,
                            m.size,
                        )

        def loader(entries: Dict[str, Tuple[str, int, int]]) -> Callable[[], _Files]:
            def read(name: str) -> bytes:
                path, offset, size = entries[name]
                with open(path, "rb") as fh:
                    fh.seek(offset)
                    return fh.read(size)

            return lambda: _Files(read, sorted(entries))

        return [(i, loader(members[i])) for i in sorted(members)]

    @staticmethod
    def _frame_prefixes(files: _Files) -> List[str]:
        # A sequence's files are in frame folders (frame_KKKK/), a single frame's are not.
        frames = sorted({k for k in map(_xbandsim.frame_of, files.names) if k is not None})
        if not frames:
            return [""]
        return [_xbandsim.frame_file(len(frames), k, "") for k in frames]

    def __len__(self) -> int:
        return len(self._samples) * len(self._frames)

    def __getitem__(self, item: int) -> Tuple[Any, Dict[str, Any]]:
        if item < 0:
            item += len(self)
        if not 0 <= item < len(self):
            raise IndexError(f"item {item} of a dataset of {len(self)}")
        k, f = divmod(item, len(self._frames))
        sample, load = self._samples[k]
        prefix = self._frames[f]
        files = load()
        try:
            png = files[prefix + self.image_file]
        except KeyError:
            raise FileNotFoundError(
                f"sample {sample} has no {prefix}{self.image_file}: the dataset's dataset.image "
                f"setting did not store it (pick image='gray' or 'colour' accordingly)"
            ) from None
        pixels = _xbandsim.decode_png(png)
        height, width = pixels.shape[:2]
        image = pixels.reshape(height, width, -1).transpose(2, 0, 1).astype(np.float32) / 255.0
        coco = json.loads(files[prefix + "coco.json"])
        annotations = coco["annotations"]
        boxes = np.array(
            [[a["bbox"][0], a["bbox"][1], a["bbox"][0] + a["bbox"][2], a["bbox"][1] + a["bbox"][3]] for a in annotations],
            dtype=np.float32,
        ).reshape(-1, 4)
        target: Dict[str, Any] = {
            "boxes": boxes,
            "labels": np.array([a["category_id"] for a in annotations], dtype=np.int64),
            "area": np.array([a["area"] for a in annotations], dtype=np.float32),
            "iscrowd": np.array([a["iscrowd"] for a in annotations], dtype=np.int64),
            # An artefact's label has no track: COCO's null is -1 here (an int64 array).
            "track_ids": np.array(
                [-1 if a["track_id"] is None else a["track_id"] for a in annotations], dtype=np.int64
            ),
            "artefacts": np.array([a.get("artefact") is not None for a in annotations], dtype=bool),
            # The COCO image id annotations.json gives this frame (the assembler's numbering:
            # sample index x frames per sample + frame + 1), also for a count= subset and on
            # the fly, so predictions score against the dataset's own annotations.
            "image_id": _xbandsim.coco_image_id(sample, len(self._frames), f),
            "sample": sample,
            "frame": f,
        }
        if self.masks:
            masks = np.zeros((len(annotations), height, width), dtype=np.uint8)
            for n, a in enumerate(annotations):
                seg = a["segmentation"]
                masks[n] = _xbandsim.decode_rle(seg["counts"], seg["size"][0], seg["size"][1])
            target["masks"] = masks
        if self.tensors:
            import torch

            image = torch.from_numpy(image)
            target = {k: torch.from_numpy(v) if isinstance(v, np.ndarray) else v for k, v in target.items()}
        if self.transforms is not None:
            image, target = self.transforms(image, target)
        return image, target

    def __repr__(self) -> str:
        return f"RadarDataset({len(self._samples)} samples x {len(self._frames)} frames)"


__all__ = ["RadarDataset"]
