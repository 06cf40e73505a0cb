"""Seeing a run: a 3D replay page in the browser (``oceangnc view RUN``) and an MCAP file for
Foxglove, Lichtblick and the ROS 2 tools (``oceangnc export RUN --mcap``); see docs/view.md.

* :mod:`oceangnc.view.run_data`: what a run folder holds for a viewer (vehicles, cable nodes, route,
  seabed, geographic origin), read once from ``log.parquet``, ``config.toml`` and ``summary.json``;
* :mod:`oceangnc.view.frames`: the frame conversions (NED to ENU for MCAP, NED to three.js);
* :mod:`oceangnc.view.mcap_export`: the MCAP writer (needs the optional package ``mcap``,
  ``pip install 'oceangnc[view]'``);
* :mod:`oceangnc.view.replay`: the self-contained replay page (three.js vendored in ``static/vendor``).
"""
