"""The foundation: the parameter file and nothing else (schema, parsing, errors, units)."""
