"""Tools every layer uses: validation, atomic files, BLAS threads, progress lines."""
