"""Is a ``setup.pip`` requirement met by what is installed? Checked with ``packaging`` (PEP 508/440).

A config lists requirement specifiers (``h5py>=3.9``, ``numpy!=2.0``, ``pkg[extra]; python_version >= "3.11"``);
hybridgen checks them against the installed distributions and never installs anything
(docs/conventions.md section 5).
"""
from __future__ import annotations

from dataclasses import dataclass

MET = "met"
MISSING = "missing"
WRONG_VERSION = "wrong version"
NOT_A_REQUIREMENT = "not a requirement"  # a URL, a pip option (-f ...), anything PEP 508 does not parse


@dataclass(frozen=True)
class RequirementCheck:
    """The outcome for one specifier: ``status`` is one of the constants above."""

    spec: str
    name: str  # canonical distribution name ("" when the spec does not parse)
    status: str
    installed: str | None = None  # the installed version, when there is one

    @property
    def met(self) -> bool:
        return self.status == MET

    def describe(self) -> str:
        """``'numpy!=2.0' (installed: 2.0.0)``-style text for messages."""
        return f"'{self.spec}'" + (f" (installed: {self.installed})" if self.installed else "")


def check_requirement(spec: str) -> RequirementCheck:
    """Check one specifier. A requirement whose environment marker is false here counts as met."""
    from importlib import metadata  # here: only configs with setup.pip pay for packaging (~10 ms)

    from packaging.requirements import InvalidRequirement, Requirement
    from packaging.utils import canonicalize_name
    from packaging.version import InvalidVersion, Version

    text = spec.strip()
    try:
        requirement = Requirement(text)
    except InvalidRequirement:
        return RequirementCheck(text, "", NOT_A_REQUIREMENT)
    name = canonicalize_name(requirement.name)
    if requirement.url:
        return RequirementCheck(text, name, NOT_A_REQUIREMENT)
    if requirement.marker is not None and not requirement.marker.evaluate():
        return RequirementCheck(text, name, MET)
    try:
        installed = metadata.version(requirement.name)
    except metadata.PackageNotFoundError:
        return RequirementCheck(text, name, MISSING)
    if not requirement.specifier:
        return RequirementCheck(text, name, MET, installed)
    try:
        version = Version(installed)
    except InvalidVersion:  # a legacy version string: compare as text, the best PEP 440 allows
        return RequirementCheck(text, name, MET if installed in requirement.specifier else WRONG_VERSION, installed)
    ok = requirement.specifier.contains(version, prereleases=True)
    return RequirementCheck(text, name, MET if ok else WRONG_VERSION, installed)


def check_requirements(specs: list[str]) -> list[RequirementCheck]:
    """:func:`check_requirement` of every specifier, in order."""
    return [check_requirement(spec) for spec in specs]
