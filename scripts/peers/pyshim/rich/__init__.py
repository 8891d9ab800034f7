"""A stand-in for the `rich` package, for machines without it.

gsplat's CUDA backend module imports `rich.console.Console` unconditionally to print build
messages. time_peers.py appends this folder to the end of sys.path, so an installed `rich`
always wins; this one only prints plain text.
"""
