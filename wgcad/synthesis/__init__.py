"""Design synthesis: from requirements to a drive (``wgcad design``, docs/models.md 14)."""
