#!/bin/sh
# The gallery's stills of the 3D replay (README, docs/view.md): two runs, and a still of each drawn by
# headless Chromium (python -m oceangnc.view.still). From the repository's root:
#     sh docs/view_stills.sh [WORKDIR]      (the runs go to WORKDIR, default $TMPDIR/oceangnc-stills)
set -e
W=${1:-${TMPDIR:-/tmp}/oceangnc-stills}
# the flagship on the benchmark's 420 m lawnmower (benchmarks/bench_view.py), 10 minutes, 20 cable segments
ROUTE='[[0, 0], [120, 0], [120, 30], [0, 30], [0, 60], [120, 60]]'
python -m oceangnc run combined-survey --duration 600 --set cable.segments=20 --set "guidance.waypoints=$ROUTE" \
    --no-plots --quiet --out "$W/combined-survey" --overwrite
python -m oceangnc.view.still "$W/combined-survey" docs/img/replay_combined_survey.png --t 230
# the tow in an irregular sea: tow-sea-state's JONSWAP Hs 1 m, Tp 6 s, 128 components, 20 cable segments
python -m oceangnc run tow-sea-state --duration 120 --set cable.segments=20 --no-plots --quiet \
    --out "$W/tow-sea-state" --overwrite
python -m oceangnc.view.still "$W/tow-sea-state" docs/img/replay_tow_sea_state.png --t 90 --azimuth -100 --elevation 22 --distance 40
