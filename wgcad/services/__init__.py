"""What runs a model for a command, as a library call: a design file through its model to the record and the
document the command writes (the audit with its NOT CHECKED notes, 3D check and baseline; the KE run with its
loaded states and installation scan). The CLI and :mod:`wgcad.api` only call these; :mod:`wgcad.report` words
and rounds their figures."""
