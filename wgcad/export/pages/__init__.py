"""The interactive pages (``--html``): one self-contained HTML file each, in the frame of
:mod:`wgcad.export.pages.frame`."""
