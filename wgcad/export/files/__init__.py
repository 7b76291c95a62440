"""What each command writes, as a library call: the files of a drive, an audit, a sectored gear, a design search
and the part set, each written in one atomic batch after everything is built."""
