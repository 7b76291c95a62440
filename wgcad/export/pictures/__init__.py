"""The PNG pictures (matplotlib): what each shows is computed in its module from the results, drawn by
:mod:`wgcad.export.pictures.drive`'s helpers and rendered by :mod:`wgcad.export.pictures.mpl`."""
