"""OpenCV, imported when a post-processing function that needs it is called (it is not a hybridgen dependency)."""
from __future__ import annotations

from types import ModuleType


def require_cv2(call: str, contrib: bool = False) -> ModuleType:
    """The ``cv2`` module, or an ImportError of one line naming ``call`` and the package to install (with
    ``contrib``: OpenCV's contrib modules, e.g. ``cv2.ximgproc``)."""
    package = "opencv-contrib-python-headless" if contrib else "opencv-python-headless"
    try:
        import cv2
    except ImportError:
        raise ImportError(f"{call} needs OpenCV: pip install {package}") from None
    if contrib and not hasattr(cv2, "ximgproc"):
        raise ImportError(f"{call} needs OpenCV's contrib modules (cv2.ximgproc): pip install {package}")
    return cv2
