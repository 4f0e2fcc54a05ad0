# Writes tests/data/generated-two-arrays.npz (run from the repository root) (numpy.savez_compressed): a 3 x 4 map "heights"
# (0 … 11, row-major) and a 1-D array "x" that an .npz reader must leave out.
import numpy as np
np.savez_compressed("tests/data/generated-two-arrays.npz", x=np.arange(5.0), heights=np.arange(12.0).reshape(3, 4))
