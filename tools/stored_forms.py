"""The forms in which a default HDF5 file stores the label passes (packed targets: float32 depth, octahedral normal
codes, narrowed ids), asked of a real writer: a sink that stores nothing can take the passes in those forms, so
that the renderer makes what an end-to-end run makes (tools/bench_labels.py, tools/bench_writer.py)."""
from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any


def default_file_encodings(n: int, layouts: list[Any], records: dict[str, Any],
                           attributes: dict[str, Any]) -> dict[str, str]:
    """``accepted_encodings()`` of an ``Hdf5SingleFileWriter`` begun with these arguments (a probe file in a
    temporary folder, aborted)."""
    import hybridgen as hg

    with tempfile.TemporaryDirectory() as tmp:
        probe = hg.Hdf5SingleFileWriter(Path(tmp) / "probe.hdf5")
        probe.begin(n, layouts, records, attributes)
        encodings = probe.accepted_encodings()
        probe.abort()
    return encodings
