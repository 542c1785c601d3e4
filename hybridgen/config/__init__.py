"""Configs: YAML files of ordered modules (``setup`` / ``global`` / ``modules``, ``<args:N>``) read, resolved and
checked before anything runs; module parameter declarations (:mod:`.schema`), module roles (:mod:`.roles`), the
module registry (:mod:`.registry`) and the translation of BlenderProc 1.x configs (:mod:`.blenderproc`).

May import: ``hybridgen.sampling`` (configs hold samplers), ``hybridgen.scene`` and the top-level helpers. The
module classes are reached through the registry at run time, never imported here (docs/architecture.md).
"""
