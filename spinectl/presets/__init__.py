"""Built-in parameter presets, one TOML file each (see :mod:`spinectl.model.config`)."""
