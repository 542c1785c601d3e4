"""A local Ray cluster reachable from this machine only.

``ray.init(_node_ip_address="127.0.0.1")`` is not enough (Ray 2.60, measured): Ray replaces a loopback node
address with the machine's remotely reachable one (``services.resolve_ip_for_localhost``), and its GCS,
raylet, workers and agents then listen on that address or on all interfaces (``::``). The node address is
only kept on loopback when Ray believes it runs without a cluster - the switch Ray uses on Windows and
macOS, ``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0``. :func:`keep_ray_on_loopback` sets it for this process (Ray
reads it once, when imported, so the parsed value is set too) and for the processes Ray starts.
``tests/run/test_locking_signals.py`` checks every listening socket of a run's Ray processes.
"""
from __future__ import annotations

import os

CLUSTER_SWITCH = "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"


def keep_ray_on_loopback() -> None:
    """Make the next ``ray.init`` that starts a local cluster put every Ray service on 127.0.0.1.
    Call before ``ray.init``; connecting to an existing cluster (an address) is not affected."""
    os.environ[CLUSTER_SWITCH] = "0"
    from ray._private import ray_constants

    ray_constants.ENABLE_RAY_CLUSTER = False
