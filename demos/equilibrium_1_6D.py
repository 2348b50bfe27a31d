"""1-6(D) deployable system (7.4.2): our designs beside Tables 7.4 and 7.5.

Run: .venv/bin/python demos/equilibrium_1_6D.py
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from equilibrium_1_4D import deployable_table  # noqa: E402

if __name__ == "__main__":
    print(deployable_table("1-6D", "7.5"))
