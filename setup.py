"""Builds the one compiled module, ``acld_gym.envs._stepcore`` (the env's step in C).

Everything else is declared in pyproject.toml. The extension is optional: without
a C compiler the install still succeeds and ``ACLDBeamEnv`` steps in numpy
(``acld_gym.envs.beam_env.COMPILED_STEP`` tells which).
"""

import numpy as np
from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "acld_gym.envs._stepcore",
            ["acld_gym/envs/_stepcore.c"],
            include_dirs=[np.get_include()],
            extra_compile_args=["-O3"],
            optional=True,
        )
    ]
)
