"""Export: generated code (NumPy, C) from any result through one dispatch, the SVG line plots, and JSON (json.py: ``to_jsonable`` and the ``JsonExport`` mixin every result class exports itself through).

The public names are re-exported by :mod:`lindstedt`.
"""
