"""Labels by rasterization: everything that draws with OpenGL, and the label passes made from what it reads back.

Owns the headless GL context (:mod:`.gl_context`) and the threads that own one (:mod:`.gl_worker`,
:mod:`.threaded_labels`), the raster view of a scene (:mod:`.raster_view`: geometry uploaded once, one MRT draw
per keypoint, :mod:`.readback`), its framebuffers, shaders and culling (:mod:`.framebuffer_ring`,
:mod:`.shader_source`, :mod:`.triangle_clusters`, :mod:`.cluster_cache`, :mod:`.face_planes`,
:mod:`.alpha_cutout`), single-object silhouettes, and the passes computed from a keypoint's readback
(:mod:`.raster_passes`, :mod:`.geometry_passes`, :mod:`.object_passes`, :mod:`.object_records`, through
:mod:`.keypoint_frame`). Entry point: :func:`.render_labels.render_labels`.

May import: ``hybridgen.render``'s shared modules (the pass catalogue, the keypoint loop, material maps, shared
geometry), ``hybridgen.scene``, ``hybridgen.io`` (sinks, label encodings) and the package's top-level helpers.
Never imports :mod:`hybridgen.render.pathtrace`, Mitsuba or Dr.Jit: a labels-only run loads no color code.
"""
