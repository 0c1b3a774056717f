"""sph-surge solver: a compact 2D weakly-compressible SPH engine (SPEC section 6)."""
__version__ = "0.1.0"

from .scene import Scene, SceneError, load_scene, scene_from_dict  # noqa: E402,F401
