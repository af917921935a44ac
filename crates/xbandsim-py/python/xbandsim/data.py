"""``RadarDataset``: a generated dataset as (image, target) pairs for training detectors.

It reads a dataset folder made by ``xbandsim dataset`` or ``xbandsim.dataset.generate``
(sample folders or WebDataset tar shards), or renders samples on the fly from a dataset spec.
Items follow torchvision's detection convention::

    image   float32 (C, H, W) in [0, 1]  (C = 1 for ppi_gray.png, 3 for ppi.png)
    target  {"boxes": (N, 4) float32 x0 y0 x1 y1 in pixels, "labels": (N,) int64 category ids,
             "masks": (N, H, W) uint8, "area": (N,) float32, "iscrowd": (N,) int64,
             "track_ids": (N,) int64, "image_id": int, "sample": int, "frame": int}

NumPy arrays without torch; torch tensors when torch is installed (or ``tensors=True``), so
that ``torch.utils.data.DataLoader(ds, collate_fn=lambda b: tuple(zip(*b)))`` works. The
labels are the dataset's own COCO annotations (docs/formats.md, "Dataset labels"): an object
gets a box only where it can be seen; the masks decode the COCO RLE of each target's own
returns.
"""

import json
import os
import re
import tarfile
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _xbandsim

PathLike = Union[str, "os.PathLike[str]"]

_MEMBER = re.compile(r"^(\d{9})\.(.+)$")


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
        if image not in ("gray", "colour"):
            raise ValueError(f"image {image!r}: must be 'gray' or 'colour'")
        self.image_file = "ppi_gray.png" if image == "gray" else "ppi.png"
        self.masks = masks
        self.transforms = transforms
        if tensors is None:
            try:
                import torch  # noqa: F401

                tensors = True
            except ImportError:
                tensors = False
        self.tensors = tensors
        source = os.fspath(source)
        self._spec: Optional[str] = None
        self._samples: List[Tuple[int, Callable[[], _Files]]] = []
        if os.path.isfile(source) and source.endswith(".toml"):
            if count is None or count < 1:
                raise ValueError("a dataset spec needs count >= 1 samples to render")
            self._spec, self._seed = source, int(seed)
            self._samples = [(i, self._render_closure(i)) for i in range(int(count))]
        elif os.path.isdir(os.path.join(source, "samples")):
            self._samples = self._scan_folders(os.path.join(source, "samples"))
        elif os.path.isdir(os.path.join(source, "shards")):
            self._samples = self._scan_shards(os.path.join(source, "shards"))
        else:
            raise FileNotFoundError(
                f"{source}: neither a dataset folder (with samples/ or shards/) nor a dataset spec .toml"
            )
        if count is not None and self._spec is None:
            self._samples = self._samples[: int(count)]
        # One item per (sample, frame): the frame folders are found in the first sample.
        self._frames = self._frame_prefixes(self._samples[0][1]()) if self._samples else [""]

    def _render_closure(self, index: int) -> Callable[[], _Files]:
        def load() -> _Files:
            files = dict(_xbandsim.render_sample(self._spec, self._seed, index))
            return _Files(files.__getitem__, sorted(files))

        return load

    @staticmethod
    def _scan_folders(root: str) -> List[Tuple[int, Callable[[], _Files]]]:
        out = []
        for group in sorted(os.listdir(root)):
            gdir = os.path.join(root, group)
            if not os.path.isdir(gdir):
                continue
            for name in sorted(os.listdir(gdir)):
                folder = os.path.join(gdir, name)
                if name.isdigit() and os.path.isdir(folder):
                    out.append((int(name), (lambda f=folder: _folder_sample(f))))
        return sorted(out, key=lambda s: s[0])

    @staticmethod
    def _scan_shards(root: str) -> List[Tuple[int, Callable[[], _Files]]]:
        # Index every member's byte range once; items read their bytes with one seek each.
        members: Dict[int, Dict[str, Tuple[str, int, int]]] = {}
        for shard in sorted(f for f in os.listdir(root) if f.endswith(".tar")):
            path = os.path.join(root, shard)
            with tarfile.open(path) as tar:
                for m in tar.getmembers():
                    hit = _MEMBER.match(m.name)
                    if m.isfile() and hit:
                        members.setdefault(int(hit.group(1)), {})[hit.group(2)] = (
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
        frames = sorted({n.split("/")[0] + "/" for n in files.names if n.startswith("frame_")})
        return frames or [""]

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
            "track_ids": np.array([a["track_id"] for a in annotations], dtype=np.int64),
            "image_id": item,
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
