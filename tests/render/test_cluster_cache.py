"""Triangle clusters built once (hybridgen/render/raster/cluster_cache.py): a memo or disk hit gives exactly what a fresh
build gives, content decides (an edited mesh is built again), a damaged entry is a miss, raster threads
uploading one mesh at once build it once, ``HYBRIDGEN_CACHE_DIR=off`` writes nothing, and the clusters of a
flat mesh's corner vertices (what the raster view uploads) equal those of its own arrays."""
from __future__ import annotations

import threading

import numpy as np
import pytest

from hybridgen.render.raster import cluster_cache
from hybridgen.render.raster.cluster_cache import mesh_clusters
from hybridgen.render.raster.triangle_clusters import MIN_TRIANGLES, build_clusters
from tests.render.test_cluster_culling import _grid


def _same(a, b) -> None:
    for name in cluster_cache._FIELDS:
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape and np.array_equal(x, y), name


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", str(tmp_path / "cache"))
    cluster_cache.clear_memo()
    yield tmp_path / "cache" / "clusters"
    cluster_cache.clear_memo()


def _counting(monkeypatch) -> list[int]:
    calls: list[int] = []

    def counted(vertices, faces):
        calls.append(len(faces))
        return build_clusters(vertices, faces)

    monkeypatch.setattr(cluster_cache, "build_clusters", counted)
    return calls


def test_memo_and_disk_hits_equal_a_fresh_build(cache_dir, monkeypatch):
    vertices, faces = _grid(50)  # 5000 triangles
    fresh = build_clusters(vertices, faces)
    calls = _counting(monkeypatch)
    first = mesh_clusters(vertices, faces)
    _same(first, fresh)
    assert calls == [len(faces)] and len(list(cache_dir.glob("*.npz"))) == 1
    assert mesh_clusters(vertices.copy(), faces.copy()) is first  # memo: same content, other arrays
    cluster_cache.clear_memo()
    from_disk = mesh_clusters(vertices, faces)
    _same(from_disk, fresh)
    assert calls == [len(faces)]  # neither hit built
    assert not from_disk.corners.flags.writeable and not first.reach.flags.writeable
    assert mesh_clusters(vertices, faces[:MIN_TRIANGLES - 1]) is None


def test_content_decides_and_a_damaged_entry_is_a_miss(cache_dir, monkeypatch):
    vertices, faces = _grid(50)
    calls = _counting(monkeypatch)
    mesh_clusters(vertices, faces)
    moved = vertices.copy()
    moved[7, 2] += 0.25  # one vertex of the first cluster lifted: its box grows
    cluster_cache.clear_memo()
    edited = mesh_clusters(moved, faces)
    _same(edited, build_clusters(moved, faces))
    assert edited.corners[0, :, 2].max() == 0.25 and len(calls) == 2
    for entry in cache_dir.glob("*.npz"):
        entry.write_bytes(entry.read_bytes()[:100])  # truncated
    cluster_cache.clear_memo()
    _same(mesh_clusters(vertices, faces), build_clusters(vertices, faces))
    assert len(calls) == 3  # built again, and the entry rewritten whole
    cluster_cache.clear_memo()
    mesh_clusters(vertices, faces)
    assert len(calls) == 3


def test_threads_uploading_one_mesh_build_it_once(cache_dir, monkeypatch):
    vertices, faces = _grid(60)
    calls = _counting(monkeypatch)
    start = threading.Barrier(4)
    results = []

    def upload() -> None:
        start.wait()
        results.append(mesh_clusters(vertices, faces))

    threads = [threading.Thread(target=upload) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(calls) == 1 and len(results) == 4 and all(r is results[0] for r in results)


def test_cache_off_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", "off")
    monkeypatch.chdir(tmp_path)
    cluster_cache.clear_memo()
    vertices, faces = _grid(50)
    _same(mesh_clusters(vertices, faces), build_clusters(vertices, faces))
    assert list(tmp_path.iterdir()) == []
    cluster_cache.clear_memo()


def test_flat_mesh_corner_vertices_give_the_same_clusters():
    vertices, faces = _grid(50)
    order = faces.ravel()  # what RasterView uploads for a mesh without vertex normals
    corners = build_clusters(vertices[order], np.arange(len(order)).reshape(-1, 3))
    _same(corners, build_clusters(vertices, faces))


def test_a_cache_that_cannot_be_written_is_skipped(tmp_path, monkeypatch):
    (tmp_path / "cache").write_text("a file where the cache folder would be")
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", str(tmp_path / "cache"))
    cluster_cache.clear_memo()
    vertices, faces = _grid(50)
    _same(mesh_clusters(vertices, faces), build_clusters(vertices, faces))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cache"]
    cluster_cache.clear_memo()
