"""The ugl-bench external-learner protocol helper, for the programs of this folder.

Its one implementation is the Python package's module `python/ugl_bench/protocol.py` (numpy
only, importable without building the package). This file loads it by path, so that
`from ugl_protocol import serve` works here without installing anything. In your own program,
either `pip install ./python` and `from ugl_bench.protocol import serve`, or copy
`python/ugl_bench/protocol.py` beside it as `ugl_protocol.py`.
"""
import importlib.util
import os

_PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python", "ugl_bench", "protocol.py")
_spec = importlib.util.spec_from_file_location("ugl_protocol_impl", _PATH)
_impl = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_impl)

serve = _impl.serve
serve_object = _impl.serve_object
read_npy = _impl.read_npy
write_npy = _impl.write_npy
read_exact = _impl.read_exact
