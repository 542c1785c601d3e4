"""Rendering: the views that turn the scene model into per-keypoint values, and the loop that hands them to sinks.

Three rooms (docs/architecture.md):

- :mod:`hybridgen.render.raster` draws the labels with OpenGL (moderngl, headless EGL): the GL context and its
  worker threads, the multiple-render-target draw, readback, triangle clusters, silhouettes and the label passes
  made from a readback (depth, normals, ids, flow, NOCS, per-object records). Entry point:
  :func:`hybridgen.render.raster.render_labels.render_labels`.
- :mod:`hybridgen.render.pathtrace` renders color with Mitsuba 3: scene export, materials, sensors, the
  integrators, adaptive sampling, Owen-scrambled Sobol samples, light selection, glossy filtering, transparent
  shadows, specular denoising guides and Open Image Denoise.
- This package's own modules hold what both sides use or what joins them: the pass catalogue (:mod:`.passes`:
  every output key, declared once, bound to the function that makes it), the keypoint loop (:mod:`.keypoint_loop`),
  material map decoding and shared-geometry detection (used by the rasterizer and the Mitsuba export alike), the
  pixel filter, the tonemap, and the color entry point (:mod:`.render_color`) with the denoiser's guide images
  (:mod:`.denoise_guides`, :mod:`.guide_worker`), which are drawn by the rasterizer and looked through glass by
  the path tracer.

Import rules (tests/test_import_graph.py): ``raster`` never imports ``pathtrace`` and ``pathtrace`` never imports
``raster``; either may import the shared modules here, and only the joining modules here (``render_color``,
``denoise_guides``, ``guide_worker``) import both sides. ``render`` imports ``scene``, ``io`` (sinks and encodings)
and the top-level helpers, never ``config``, ``modules`` or ``run``.
"""
