"""Writers: every file the twin writes goes through this package.

atomic       the one atomic writer (temporary file beside the target, then os.replace)
             and its text, JSON and CSV forms
vtk          the one field-file writer (VTU per time + ParaView .pvd) and the names and
             units of its arrays: temperature_C, displacement_um, von_mises_MPa
destinations the checks on every --out before any work starts (inputs, folders, devices)
html_pages   HTML pages from the jinja2 templates in `templates/` (package data): the
             replay, training and drift reports
figures      report figures as PNG bytes: a matplotlib Figure on the Agg canvas, no pyplot

Imports are per module (`from twin.io.atomic import write_json`): this package imports
nothing itself, so a writer never pulls in the plotting or FEM stack it does not need.
"""
