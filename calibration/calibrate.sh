#!/usr/bin/env bash
# Thin wrapper: calibration/calibrate.py does the work (docs/calibration.md).
#   bash calibration/calibrate.sh                 # every reading of calibration/readings.toml
#   bash calibration/calibrate.sh NAME...         # some readings
#   bash calibration/calibrate.sh --smoke         # the ctest calibration_smoke
exec /usr/bin/python3 "$(dirname "$0")/calibrate.py" "$@"
