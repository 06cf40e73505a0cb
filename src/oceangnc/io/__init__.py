"""Input and output: TOML configs validated with pydantic, Parquet logs, plots."""
