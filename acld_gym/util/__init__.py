"""Tools every layer uses: validation, atomic files, BLAS threads, progress lines,
aggregate statistics (IQM and bootstrap intervals)."""
