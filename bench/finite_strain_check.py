"""The estimator's neo-Hookean departure against the world's finite elements (the table of
docs/layer-law.md): ``python bench/finite_strain_check.py``; the code is
``benchmarks.finite_strain``."""

from benchmarks.finite_strain import main

if __name__ == "__main__":
    main()
