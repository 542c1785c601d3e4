"""Mitsuba's Python AD integrators, executed on first use instead of on the first switch to a JIT variant.

``mi.set_variant`` to an ``llvm_*`` / ``cuda_*`` variant imports (or reloads) ``mitsuba.python.ad.integrators``
(Mitsuba 3.9, ``src/python/alias.cpp``), whose modules (``prb``, ``prbvolpath``, ``prb_projective`` ... seven)
define their classes with ``@dr.syntax``, which parses their source again in every process: ~0.06 s of the switch's
~0.08 s. hybridgen renders with its own integrator (:mod:`hybridgen.render.pathtrace.clamped_path`) or Mitsuba's C++ ones.

:func:`defer` (before the first switch) puts each module of that package into ``sys.modules`` unexecuted
(:class:`DeferredModule`: it runs on its first attribute access other than the import system's metadata), so the
package finds them imported. :func:`register_forwarders` (after the switch) registers, for the new variant, each
integrator plugin such a module registers - read from its source: ``register_integrator("name", ...)`` - with a
factory that executes the module (whose own registration then replaces it) and creates the object through
Mitsuba's plugin manager, so ``mi.load_dict({"type": "prb"})`` and ``mi.ad.integrators.prb.PRBIntegrator`` work as
before. The standard ``importlib.util.LazyLoader`` cannot be used: the package imports with
``importlib.import_module``, which reads ``__spec__`` and so executes a lazy module.

Fails safe: a module whose source registers plugins in another form is imported as Mitsuba imports it; a module
that got executed during the switch anyway (another Mitsuba or Python) gets no forwarder, only the time is lost.
``tests/render/test_deferred_ad_integrators.py`` fails when the modules are executed during the switch or when the
names read from a source differ from what the module registers.
"""
from __future__ import annotations

import importlib.util
import pkgutil
import re
import sys
import threading
from types import ModuleType
from typing import Any

PACKAGE = "mitsuba.python.ad.integrators"
REGISTRATION = re.compile(r"""\bregister_integrator\(\s*(["'])(\w+)\1""")
METADATA = frozenset({"__spec__", "__name__", "__loader__", "__package__", "__class__"})
"""Attributes the import system reads from a module found in ``sys.modules``; any other access executes it."""


class DeferredModule(ModuleType):
    """A module created from its spec but not executed: the first access to an attribute outside
    :data:`METADATA` turns it into a plain module and executes it (once, also across threads)."""

    _lock = threading.RLock()

    def __getattribute__(self, name: str) -> Any:
        if name in METADATA:
            return super().__getattribute__(name)
        with DeferredModule._lock:
            if type(self) is DeferredModule:
                spec = super().__getattribute__("__spec__")
                self.__class__ = ModuleType
                spec.loader.exec_module(self)
        return getattr(self, name)


def is_deferred(module: ModuleType) -> bool:
    """True while ``module`` is a :class:`DeferredModule` not executed yet."""
    return type(module) is DeferredModule


def plugin_names(source: str) -> list[str] | None:
    """The integrator plugins ``source`` registers, or None when it calls ``register_integrator`` in a form
    :data:`REGISTRATION` does not read."""
    names = [match.group(2) for match in REGISTRATION.finditer(source)]
    return names if len(names) == source.count("register_integrator(") else None


def _deferred_module(name: str) -> tuple[ModuleType, list[str]] | None:
    spec = importlib.util.find_spec(name)
    if spec is None or spec.loader is None or not hasattr(spec.loader, "get_source"):
        return None
    try:
        source = spec.loader.get_source(name)
    except (ImportError, OSError):
        return None
    names = plugin_names(source) if source is not None else None
    if names is None:
        return None
    module = importlib.util.module_from_spec(spec)
    module.__class__ = DeferredModule
    return module, names


def defer() -> dict[str, list[str]]:
    """Before Mitsuba's first switch to a JIT variant: the package's modules, unexecuted, in ``sys.modules``.
    Returns module name -> the plugins it registers (for :func:`register_forwarders`); {} when there is nothing
    to defer (Mitsuba not imported, or one of the modules imported already: a JIT switch happened before)."""
    package = sys.modules.get(PACKAGE)
    if package is None or not hasattr(package, "__path__"):
        return {}
    names = sorted(f"{PACKAGE}.{info.name}" for info in pkgutil.iter_modules(package.__path__))
    if not names or any(name in sys.modules for name in names):
        return {}
    deferred: dict[str, list[str]] = {}
    for name in names:
        found = _deferred_module(name)
        if found is not None:
            sys.modules[name] = found[0]
            deferred[name] = found[1]
    return deferred


def register_forwarders(deferred: dict[str, list[str]]) -> None:
    """After the switch: each plugin of a deferred module that is still unexecuted, registered for the current
    variant with a factory that executes the module and then creates the plugin as the module's factory does."""
    import mitsuba as mi

    for module_name, plugins in deferred.items():
        module = sys.modules.get(module_name)
        if module is None or not is_deferred(module):
            continue
        for plugin in plugins:
            mi.register_integrator(plugin, _Forwarder(module_name, plugin))


class _Forwarder:
    """The factory of a deferred module's plugin until the module runs (see the module documentation)."""

    def __init__(self, module_name: str, plugin: str) -> None:
        self.module_name, self.plugin, self.used = module_name, plugin, False

    def __call__(self, props: Any) -> Any:
        import mitsuba as mi

        if self.used:  # the module ran but did not register this plugin: never loop
            raise RuntimeError(f"{self.module_name} did not register the integrator {self.plugin!r} "
                               "(hybridgen.render.pathtrace.deferred_ad_integrators)")
        self.used = True
        getattr(sys.modules[self.module_name], "__file__")  # executes the module: its own factory replaces this one
        return mi.PluginManager.instance().create_object(props)
