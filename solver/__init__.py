"""sph-surge solver: a compact 2D weakly-compressible SPH engine (docs/scheme.md section 6)."""
__version__ = "0.1.0"

from .sources import use_keyed_numba_cache

use_keyed_numba_cache()  # before any module below defines a cached kernel

from .scene import Scene, SceneError, load_scene, scene_from_dict  # noqa: E402,F401
