"""The false-alarm runner, kept here for the commands recorded in bench/results and tests/: the
machinery lives in python/lantern/testing/ (false_alarm.py and its fa_*.py families), beside the
statistics it calibrates. Same arguments:

    nice python3 tools/false_alarm.py [--trials 20] [--families cross,analytic] [--out F.json]"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))

from lantern.testing.false_alarm import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
