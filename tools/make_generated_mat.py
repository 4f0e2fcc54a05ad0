# Writes tests/data/generated-matlab.mat and tests/data/generated-matlab-compressed.mat (run from
# the repository root) with scipy.io.savemat, MATLAB level 5 format, uncompressed and compressed:
# a 3 x 4 double map "heights" (0 … 11, row-major), a 2 x 3 single "small", a string "note"
# that a reader must leave out. Generated files, not instrument files.
import numpy as np
from scipy.io import savemat

variables = {
    "heights": np.arange(12.0).reshape(3, 4),
    "small": np.array([[1.5, -2.0, 3.25], [4.0, 5.5, -6.75]], dtype=np.float32),
    "note": "not a map",
}
savemat("tests/data/generated-matlab.mat", variables, do_compression=False)
savemat("tests/data/generated-matlab-compressed.mat", variables, do_compression=True)
