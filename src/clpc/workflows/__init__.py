"""What each ``clpc`` command does, without the command line: plain functions on settings.

Each workflow takes typed settings (a frozen dataclass where there are many), may write
files, and returns a result object; :mod:`clpc.cli` only parses options, calls a workflow
and prints its result.
"""

from clpc.workflows.catalog import DatasetEntry, list_datasets
from clpc.workflows.common import (
    AppraiserSettings,
    ChannelCountError,
    RecordSpec,
    SamplingConflictError,
    SettingsError,
)
from clpc.workflows.identify import IdentifyResult, IdentifySettings, identify_file
from clpc.workflows.models import (
    CompareResult,
    CompareSettings,
    SimulateResult,
    compare_file,
    simulate_file,
)
from clpc.workflows.stream import StreamBatch, StreamSettings, stream_samples
from clpc.workflows.track import (
    Chunk,
    ChunkFilter,
    TrackResult,
    TrackSettings,
    count_data_lines,
    track_file,
)

__all__ = [
    "AppraiserSettings",
    "ChannelCountError",
    "Chunk",
    "ChunkFilter",
    "CompareResult",
    "CompareSettings",
    "DatasetEntry",
    "IdentifyResult",
    "IdentifySettings",
    "RecordSpec",
    "SamplingConflictError",
    "SettingsError",
    "SimulateResult",
    "StreamBatch",
    "StreamSettings",
    "TrackResult",
    "TrackSettings",
    "compare_file",
    "count_data_lines",
    "identify_file",
    "list_datasets",
    "simulate_file",
    "stream_samples",
    "track_file",
]
