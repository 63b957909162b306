"""The thesis's study (Rodriguez 2006): Table 2's data and metrics, its reproduction, figures
and the ``acld-gym`` command."""
