"""The tests' statistics calibrated: how often each comparison family of tests/ fails on a fair
pair (false_alarm.py and its fa_*.py families; false_alarm_nodes.py, false_alarm_coat_limb.py)
and what its negative controls resolve (measure_controls.py), beside the statistics they
measure (lantern.metrics, lantern.agreement, lantern.blocks). The families render the scenes of
a checkout's tests/ (run them from a checkout); importing this package needs neither bpy nor the
tests. tests/python/test_false_alarm.py checks the runner."""
