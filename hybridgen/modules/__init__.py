"""Config modules (``loader.ObjLoader``, ``renderer.RgbRenderer``, ``writer.Hdf5Writer``, ...): each declares its
parameters, role and keys (:mod:`.base`) and is a thin call into the Python API.

May import: everything below it (``config``, ``scene``, ``sampling``, ``render``, ``io``, ``physics``); ``run``
only for the run context's type.
"""
