"""spindle twin: a FEM-driven digital twin of a motorized spindle.

Data flows one way: spec → mesh → operators → (loads per window) → solve → fields →
metrics → report.  See the README and shared DESIGN.md for the contracts.
"""

__version__ = "0.1.0"
