"""Files in and out: mesh, texture and dataset loading (with the mesh cache), the sink protocol between renderers
and writers (:mod:`.frame_sink`), the writers (HDF5, BlenderProc HDF5, COCO, BOP, images), atomic commits, output
locks and previews.

May import: ``hybridgen.scene``, the pass catalogue's declarations (:mod:`hybridgen.render.passes`,
:mod:`hybridgen.render.tonemap`) and the top-level helpers; never GL or Mitsuba.
"""
