"""The parts of scripts/real_study.py, split by job: layouts, fits, diagnosis, physics, figures, tables."""
