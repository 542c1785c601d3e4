"""Color by path tracing with Mitsuba 3: everything that touches Mitsuba or Dr.Jit, and the denoiser.

Owns the variant choice (:mod:`.mitsuba_variant`), the export of the scene model to one Mitsuba scene
(:mod:`.mitsuba_scene`, :mod:`.mitsuba_materials`, :mod:`.mitsuba_instances`, :mod:`.material_emission`,
:mod:`.camera_hidden_emission`, :mod:`.light_selection`), the sensors (:mod:`.pinhole_sensor`,
:mod:`.thin_lens_sensor`), the integrator and what it samples with (:mod:`.clamped_path`, :mod:`.glossy_filter`,
:mod:`.transparent_shadows`, :mod:`.world_guide`, :mod:`.lobe_sampling`, :mod:`.owen_sobol`,
:mod:`.deferred_ad_integrators`), adaptive sampling (:mod:`.adaptive_sampling`), the path-trace view
(:mod:`.path_trace`), guides that look through glass (:mod:`.specular_guides`) and Open Image Denoise
(:mod:`.denoise`).

May import: ``hybridgen.render``'s shared modules (pixel filter, material maps, shared geometry),
``hybridgen.scene`` and the package's top-level helpers. Never imports :mod:`hybridgen.render.raster` or moderngl;
the guides drawn by the rasterizer reach it through :mod:`hybridgen.render.denoise_guides`.
"""
