"""Mitsuba's Python AD integrators are not executed by hybridgen's switch to a JIT variant, and still work
(hybridgen/render/pathtrace/deferred_ad_integrators.py). Fails loudly when a Mitsuba or Python update makes the switch
execute them again, or when a module registers other plugins than the names read from its source."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from hybridgen.render.pathtrace.deferred_ad_integrators import plugin_names
from hybridgen.render.pathtrace.mitsuba_variant import available_variants, variant_works
from tests.conftest import REPO

CHILD = """
import json, sys
import mitsuba as mi
from hybridgen.render.pathtrace import deferred_ad_integrators as d
from hybridgen.render.pathtrace.mitsuba_variant import activate

import pkgutil
package = sys.modules[d.PACKAGE]
modules = sorted(f"{d.PACKAGE}.{info.name}" for info in pkgutil.iter_modules(package.__path__))
activate("llvm_ad_rgb")
deferred_after_switch = [name for name in modules if d.is_deferred(sys.modules[name])]
read = {name: d.plugin_names(sys.modules[name].__spec__.loader.get_source(name)) for name in modules}

registered = {}  # what each module registers when it runs
real = mi.register_integrator
for name in modules:
    mi.register_integrator = lambda plugin, factory, name=name: (registered.setdefault(name, []).append(plugin),
                                                                 real(plugin, factory))
    getattr(sys.modules[name], "__file__")
mi.register_integrator = real

created = {plugin: type(mi.load_dict({"type": plugin})).__name__ for plugin in ("prb", "prbvolpath", "prb_basic")}
print(json.dumps({"modules": modules, "deferred_after_switch": deferred_after_switch, "read": read,
                  "registered": registered, "created": created,
                  "class": mi.ad.integrators.prb.PRBIntegrator.__name__}))
"""


@pytest.mark.skipif("llvm_ad_rgb" not in available_variants() or not variant_works("llvm_ad_rgb"),
                    reason="needs the llvm_ad_rgb variant")
def test_the_switch_leaves_them_unexecuted_and_they_load_on_first_use():
    done = subprocess.run([sys.executable, "-c", CHILD], cwd=REPO, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert len(result["modules"]) >= 2 and any(m.endswith(".prb") for m in result["modules"])
    assert result["deferred_after_switch"] == result["modules"]  # none of them ran during the switch
    for name in result["modules"]:  # the forwarders registered what each module registers when it runs
        assert sorted(result["read"][name]) == sorted(result["registered"].get(name, [])), name
    assert result["created"] == {"prb": "PRBIntegrator", "prbvolpath": "PRBVolpathIntegrator",
                                 "prb_basic": "BasicPRBIntegrator"}
    assert result["class"] == "PRBIntegrator"


def test_plugin_names_are_read_only_from_the_plain_form():
    assert plugin_names('mi.register_integrator("prb", lambda props: PRB(props))\n') == ["prb"]
    assert plugin_names("import mitsuba as mi\n") == []
    assert plugin_names("for n in NAMES:\n    mi.register_integrator(n, make(n))\n") is None  # kept eager
