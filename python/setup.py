"""`pip install ./python` is not how tcbench installs: the package's build
compiles libtcbench from the C sources beside python/, so it runs from the
repository root (`pip install .` there; python/README.md). This file only
says so, instead of pip's "Neither 'setup.py' nor 'pyproject.toml' found"."""
raise SystemExit("tcbench: install from the repository root: `pip install .` there, not ./python "
                 "(its build compiles libtcbench from the C sources; python/README.md, Installing)")
