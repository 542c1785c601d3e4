"""setup.pip requirement specifiers are checked with packaging against what is installed."""
from __future__ import annotations

from importlib import metadata

import pytest

from hybridgen.config.requirements import MET, MISSING, NOT_A_REQUIREMENT, WRONG_VERSION, check_requirement

H5PY = metadata.version("h5py")
NUMPY = metadata.version("numpy")
NUMPY_MAJOR = int(NUMPY.split(".")[0])


@pytest.mark.parametrize("spec, status", [
    ("h5py", MET),
    ("h5py>=3.0", MET),
    ("h5py>=99", WRONG_VERSION),  # used to pass: only the name was looked up
    (f"numpy!={NUMPY}", WRONG_VERSION),
    ("numpy!=0.1", MET),  # used to be 'not installed': the name was cut at '!'
    (f"numpy=={NUMPY}", MET),
    (f"numpy~={NUMPY_MAJOR}.0", MET),
    (f"numpy<{NUMPY_MAJOR}", WRONG_VERSION),
    ("NumPy >= 1.0", MET),  # names are case-insensitive, spaces allowed
    ("h5py[extra]>=3", MET),
    ('h5py>=99; python_version < "3"', MET),  # marker false here: not needed
    ('h5py>=99; python_version >= "3"', WRONG_VERSION),
    ("surely-not-installed-pkg>=1", MISSING),
    ("scikit_image", MISSING if not any(d.metadata["Name"].lower() == "scikit-image"
                                        for d in metadata.distributions()) else MET),
    ("-f https://example.org/wheels", NOT_A_REQUIREMENT),
    ("pkg @ https://example.org/pkg.whl", NOT_A_REQUIREMENT),
])
def test_requirement_status(spec, status):
    check = check_requirement(spec)
    assert check.status == status, check
    if status in (MET, WRONG_VERSION) and check.installed is not None:
        assert check.installed == metadata.version(check.name)


def test_wrong_version_message_names_the_installed_version():
    check = check_requirement("h5py>=99")
    assert check.describe() == f"'h5py>=99' (installed: {H5PY})" and check.name == "h5py"


def test_config_with_unmet_version_is_an_error(tmp_path, run_cli):
    config = tmp_path / "c.yaml"
    config.write_text("setup:\n  pip: ['surely-not-installed-pkg>=2', 'pyyaml>=99']\n"
                      "modules:\n  - name: main.Initializer\n")
    code, _, err = run_cli("run", str(config))
    assert code == 2
    assert "setup.pip" in err and "'surely-not-installed-pkg>=2'" in err
    assert "pip install 'surely-not-installed-pkg>=2'" in err
    # pyyaml is one of the packages BlenderProc installs into Blender's Python: a notice, not an error
    assert "pyyaml>=99" not in err.splitlines()[-1]
