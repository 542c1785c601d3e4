"""HDF5 filters that do not come with HDF5 itself (Blosc2), for every reader and writer of hybridgen's files.

``data.hdf5`` written with ``compression: blosc2`` stores its image chunks through the Blosc2 filter (HDF5
filter id 32026, registered by the ``hdf5plugin`` package). A plain h5py user reads such a file after
``pip install hdf5plugin`` and ``import hdf5plugin`` (before opening it); gzip files (the default) need
nothing. Every reader in this package calls :func:`enable_filters` before it opens a file.
"""
from __future__ import annotations

from functools import lru_cache

BLOSC2_FILTER_ID = 32026
"""HDF5's registered id of the Blosc2 filter (hdf5plugin, PyTables' hdf5-blosc2)."""

READ_HINT = "pip install hdf5plugin; import hdf5plugin before h5py opens the file"
"""How a plain h5py user reads a file whose datasets use the Blosc2 filter (stored in its attributes)."""


@lru_cache(maxsize=1)
def enable_filters() -> bool:
    """Registers hdf5plugin's filters with the HDF5 library h5py uses (once per process); False when
    hdf5plugin is not installed (gzip files still read; a Blosc2 dataset then fails to read, naming its filter)."""
    try:
        import hdf5plugin  # noqa: F401  (importing registers the filters)
    except ImportError:  # pragma: no cover - hdf5plugin is a dependency
        return False
    return True
