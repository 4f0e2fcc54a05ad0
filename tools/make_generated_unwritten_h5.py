# Writes tests/data/generated-unwritten-chunks.h5 (run from the repository root) (h5py 3.16): a
# 16384 x 16384 float64 dataset "heights", gzip-chunked in 1024 x 1024 chunks, none of them
# written: 1.4 KB declaring 2 GiB of values, all the fill value.
import h5py
with h5py.File("tests/data/generated-unwritten-chunks.h5", "w", libver="earliest") as f:
    f.create_dataset("heights", shape=(16384, 16384), dtype="f8", chunks=(1024, 1024), compression="gzip")
