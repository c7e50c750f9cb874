"""Fast frame windows for LeRobot's dataset loader: numeric columns read once, then indexed in memory.

A policy trained on sequences (BC-RNN: 10 frames of every observation and action) makes
``LeRobotDataset`` fetch a window per key per sample. In lerobot 0.6 with ``datasets`` >= 4.4 each
fetch builds a lazy column (a deep copy of the dataset's features) and then formats whole rows, so
the data loader, not the model, bounds training: about 6 ms a sample, 0.5 s a step of batch 100 on
2 cores (upstream: huggingface/lerobot#3523). This reader keeps each queried numeric column as one
tensor per process and slices it: the same tensors (dtype, shape, values; tests/test_frame_cache.py
compares every key against LeRobot's own reader), about 25 times faster a sample.

Whole samples come from memory too when every column of the dataset is numeric and no frame is a
video: the current row and the episode bounds (LeRobot indexes an Arrow table for each, which was
most of a loader worker's time once the windows were cached). Any other dataset keeps LeRobot's
row lookup and only its windows are cached.

It is LeRobot's ``DatasetReader`` with three methods overridden, installed by importing the BC-RNN
plugin (so every ``lerobot-train`` in an environment that has this project uses it); set
``IGEN_FRAME_CACHE=0`` to train with LeRobot's reader unchanged.
"""

from __future__ import annotations

import logging
import os

import numpy as np
import torch
from lerobot.datasets import lerobot_dataset
from lerobot.datasets.dataset_reader import DatasetReader

logger = logging.getLogger(__name__)

ENV_SWITCH = "IGEN_FRAME_CACHE"
NUMERIC_DTYPES = {"float16", "float32", "float64", "int8", "int16", "int32", "int64", "uint8", "bool"}
MAX_COLUMN_BYTES = 1 << 30  # a column larger than this stays on LeRobot's path (memory per loader worker)


class CachedFrameReader(DatasetReader):
    """``DatasetReader`` whose frame windows of numeric features come from in-memory columns.

    Keys it does not hold (videos, images, strings, nested shapes, oversized columns) go through
    LeRobot's own query, so the result is the same for any dataset.
    """

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        for held in ("_frame_columns", "_row_columns", "_bounds"):
            state.pop(held, None)  # rebuilt by each loader worker, not shipped to it
        return state

    def get_item(self, idx) -> dict:
        """LeRobot's sample (``DatasetReader.get_item``) read from held columns, when all are numeric."""
        rows = self._rows_for(self.hf_dataset)
        if rows is None:
            return super().get_item(idx)
        item = {key: column[idx] for key, column in rows.items()}
        if self.delta_indices is not None:
            query_indices, padding = self._get_query_indices(int(item["index"]), int(item["episode_index"]))
            item = {**item, **padding, **self._query_hf_dataset(query_indices)}
        item["task"] = self._meta.tasks.iloc[int(item["task_index"])].name
        return item

    def _get_query_indices(self, abs_idx: int, ep_idx: int) -> tuple[dict[str, list[int]], dict[str, torch.Tensor]]:
        """LeRobot's window indices and padding flags, with the episode's bounds read from memory."""
        starts, ends = self._episode_bounds()
        ep_start, ep_end = int(starts[ep_idx]), int(ends[ep_idx])
        query_indices = {
            key: [max(ep_start, min(ep_end - 1, abs_idx + delta)) for delta in deltas]
            for key, deltas in self.delta_indices.items()
        }
        padding = {
            f"{key}_is_pad": torch.BoolTensor([not ep_start <= abs_idx + delta < ep_end for delta in deltas])
            for key, deltas in self.delta_indices.items()
        }
        return query_indices, padding

    def _episode_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Every episode's first and one-past-last frame index, by episode index."""
        held = getattr(self, "_bounds", None)
        if held is None:
            columns = ["episode_index", "dataset_from_index", "dataset_to_index"]
            episodes = self._meta.episodes.with_format("numpy", columns=columns)[:]
            size = int(episodes["episode_index"].max()) + 1
            starts, ends = np.full(size, -1, np.int64), np.full(size, -1, np.int64)
            starts[episodes["episode_index"]] = episodes["dataset_from_index"]
            ends[episodes["episode_index"]] = episodes["dataset_to_index"]
            held = self._bounds = (starts, ends)
        return held

    def _rows_for(self, hf_dataset) -> dict[str, torch.Tensor] | None:
        """Every column of ``hf_dataset`` held in memory, or None where a sample needs LeRobot's path."""
        held = getattr(self, "_row_columns", None)
        token = (id(hf_dataset), len(hf_dataset))
        if held is None or held[0] != token:
            names = hf_dataset.column_names
            columns = None
            if not self._meta.video_keys and all(self._cacheable(key) for key in names):
                windows = self._columns_for(hf_dataset)
                columns = {key: windows[key] if key in windows else _column_as_torch(hf_dataset, key) for key in names}
            held = self._row_columns = (token, columns)
        return held[1]

    def _query_hf_dataset(self, query_indices: dict[str, list[int]]) -> dict:
        columns = self._columns_for(self.hf_dataset)
        cached = {key: q for key, q in query_indices.items() if key in columns}
        result = super()._query_hf_dataset({k: q for k, q in query_indices.items() if k not in cached})
        to_relative = self._absolute_to_relative_idx
        for key, q_idx in cached.items():
            rows = q_idx if to_relative is None else [to_relative[i] for i in q_idx]
            result[key] = columns[key][rows]
        return result

    def _columns_for(self, hf_dataset) -> dict[str, torch.Tensor]:
        """The cached columns of ``hf_dataset`` (rebuilt when the reader loads another one)."""
        held = getattr(self, "_frame_columns", None)
        token = (id(hf_dataset), len(hf_dataset))
        if held is None or held[0] != token:
            keys = [key for key in self.delta_indices or {} if self._cacheable(key)]
            held = (token, {key: _column_as_torch(hf_dataset, key) for key in keys})
            self._frame_columns = held
        return held[1]

    def _cacheable(self, key: str) -> bool:
        feature = self._meta.features.get(key)
        if feature is None or key in self._meta.video_keys or feature.get("dtype") not in NUMERIC_DTYPES:
            return False
        shape = tuple(feature.get("shape") or ())
        if len(shape) > 1:
            return False
        itemsize = np.dtype(feature["dtype"]).itemsize
        return self.hf_dataset.num_rows * int(np.prod(shape or (1,))) * itemsize <= MAX_COLUMN_BYTES


def _column_as_torch(hf_dataset, key: str) -> torch.Tensor:
    """One column as a tensor of the dtype LeRobot's transform gives (``torch.tensor`` of Python values)."""
    values = np.asarray(hf_dataset.with_format("numpy", columns=[key])[:][key])
    if values.dtype == np.bool_:
        return torch.from_numpy(values.copy())
    if np.issubdtype(values.dtype, np.floating):
        return torch.from_numpy(values).to(torch.get_default_dtype())
    return torch.from_numpy(values.astype(np.int64))


def install() -> bool:
    """Make ``LeRobotDataset`` read through ``CachedFrameReader`` (unless ``IGEN_FRAME_CACHE=0``)."""
    if os.environ.get(ENV_SWITCH, "1") == "0":
        return False
    if not hasattr(DatasetReader, "_query_hf_dataset") or getattr(lerobot_dataset, "DatasetReader", None) is None:
        logger.warning("this lerobot has no DatasetReader._query_hf_dataset: frame cache not installed")
        return False
    if lerobot_dataset.DatasetReader is not CachedFrameReader:
        lerobot_dataset.DatasetReader = CachedFrameReader
        logger.info("LeRobotDataset reads frame windows through %s (%s=0 turns it off)", __name__, ENV_SWITCH)
    return True


def installed() -> bool:
    """Whether ``LeRobotDataset`` currently reads through the cache."""
    return lerobot_dataset.DatasetReader is CachedFrameReader
