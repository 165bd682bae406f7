"""planarvo.plot: figures a paper would show, and a one-file calibration report, from planarvo's
output files (matplotlib, Agg backend).

    python3 -m planarvo.plot track DATASET --trajectory traj.txt --stats stats.csv --out-dir figs
    python3 -m planarvo.plot calibration DATASET --extrinsics calib.yaml --report report.html

The `planarvo plot` command runs the same. Modules: _cli (the command line), _style (sizes, fonts,
colours, saving), _io (reading the files), _motion (matching, velocities, fits, status spans),
_trajectory, _velocity, _tracking (the track figures), _track (the track subcommand),
_calibration_data (motion pairs, windows, calibrations; the residuals are the library's),
_calibration_figures, _calibration_command, _report (HTML)."""
