"""rmapgen's bit-accurate model of the reflectance-map shader, over numpy arrays.

The same Rust crate as the ``rmapgen`` command line (docs/PYTHON.md)::

    import numpy as np, rmapgen
    d = rmapgen.Design(rmapgen.Config(grad_bits=12), rmapgen.Scene.standard())
    g, xy = rmapgen.sphere(d.config, 256)
    out = d.shade(g)                       # the hardware's intensities, bit for bit
    ref = d.reference(g)                   # the float light model, quantised
    print(rmapgen.metrics(out, ref, d.peak)["max_abs_error"])
    path = d.trace(g[:1])                  # every port of every stage, by Verilog name
    n = np.array([[0.6, 0.0, 0.8]])        # float normals, unit or not, ...
    print(rmapgen.quantize(n, d.config))   # ... as gradients: [[1535    0 2047]]

``Config`` takes the fields of ``config.toml``, ``Scene`` reads the files of ``scenes/``,
``Design`` holds every ROM and map ``rmapgen generate`` would write. Arguments are read
exactly or refused (docs/PYTHON.md, "What the package refuses"): floats are not gradients.
"""

from ._rmapgen import TRACE_MAX, Config, Design, Scene, metrics, quantize, sphere

__all__ = ["Config", "Design", "Scene", "metrics", "quantize", "sphere", "TRACE_MAX"]
