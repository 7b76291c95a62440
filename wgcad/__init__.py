"""wgcad: geometry, deformation and clearance of harmonic (strain-wave) drives."""

__version__ = "0.1.0"
__all__ = ["__version__"]
