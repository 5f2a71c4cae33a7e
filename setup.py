"""Installs robostrich_suite (simulation), agents (JAX SAC learner) and the console commands' launcher.

Versions are pinned to a set that works together: mujoco 4.0 breaks
dm-control 1.0.50, and dm-haiku 0.0.17 is the last haiku release, tested
here with jax 0.10.2.
"""
from setuptools import find_packages, setup

setup(
    name="robostrich_suite",
    version="0.1.0",
    description="Simulation and curriculum-SAC learning for the tendon-driven Robostrich arm.",
    license="Apache-2.0",  # the text: LICENSE (as dm_control, Acme and MuJoCo)
    classifiers=["License :: OSI Approved :: Apache Software License"],
    python_requires=">=3.11",  # numpy 2.4, jax 0.10, scipy, matplotlib 3.11 and rerun-sdk 0.41 need 3.11
    packages=find_packages(include=["robostrich_suite", "robostrich_suite.*", "agents", "agents.*"]),
    # robostrich_commands.py: the console scripts' light launcher, beside the packages (its docstring says why)
    py_modules=["robostrich_commands"],
    package_data={"robostrich_suite": ["data/*", "data/policies/*", "data/new_targets/*", "data/help/*", "data/arms/*"]},
    install_requires=[
        "mujoco==3.17.0",
        "dm-control==1.0.50",
        "dm-env==1.6",
        "numpy==2.4.6",
        "jax==0.10.2",
        "jaxlib==0.10.2",
        "ml_dtypes==0.6.0",  # jax's own requirement, pinned: importing 0.7.0 adds half a second to every command's start
        "dm-haiku==0.0.17",
        "optax==0.2.8",
        "rerun-sdk==0.41.0",
        "matplotlib==3.11.2",  # figures (PNG) for the paper's plots
        "tqdm==4.70.1",  # progress bars on training and sampling
        "scipy==1.17.1",  # gap_bound's least_squares over the joint angles (jax already installs it)
    ],
    extras_require={
        # ray: the sweep's tests start a local Ray, and CI installs only this extra
        # optuna: robostrich-design's tests run a search (tests/test_design.py), and CI installs only this extra
        # and the peers' pins (the same as "peers" below; extras here are literal lists, which
        # tests/test_setup.py reads): tests/test_peers.py runs each peer a few steps through the adapter
        # playwright: tests/test_web_viewer.py drives the system's Chromium (never a downloaded one) on --web's page
        # nbclient, nbformat, ipykernel, rerun-notebook: tests/test_tutorial.py runs docs/tutorial.ipynb top to bottom
        "test": ["pytest==9.2.0", "pytest-xdist==3.8.0", "gymnasium==1.4.0", "ray==2.60.0", "optuna==5.1.0",
                 "sbx-rl==0.28.0", "stable-baselines3==2.9.2", "flax==0.12.8", "torch==2.13.0",
                 "tfp-nightly==0.26.0.dev20261027",
                 "playwright==1.65.3", "nbclient==0.11.0", "nbformat==5.11.1", "ipykernel==7.4.0",
                 "rerun-notebook==0.41.0"],
        # docs/tutorial.ipynb, its recording inline, and jupyter nbconvert --execute, as the notebook says to run it
        "notebook": ["ipykernel==7.4.0", "rerun-notebook==0.41.0", "nbconvert==7.17.2"],
        "gym": ["gymnasium==1.4.0"],
        "sweep": ["ray==2.60.0"],  # robostrich-sweep: grids of runs as Ray tasks
        "design": ["optuna==5.1.0"],  # robostrich-design: the routing search (its study in SQLite via SQLAlchemy)
        # tools/benchmark_peers.py: SBX's SAC, TQC and CrossQ beside ours. SBX 0.28 on flax 0.12.8 runs
        # with jax 0.10.2 and gymnasium 1.4.0; stable-baselines3 needs torch, pinned to 2.13.0, whose CPU
        # wheel pip takes (unpinned, pip would pull a multi-GB CUDA build); sbx leaves tfp-nightly unpinned.
        "peers": ["gymnasium==1.4.0", "sbx-rl==0.28.0", "stable-baselines3==2.9.2", "flax==0.12.8", "torch==2.13.0",
                  "tfp-nightly==0.26.0.dev20261027"],
    },
    entry_points={
        "console_scripts": [
            "robostrich-train = robostrich_commands:train",
            "robostrich-evaluate = robostrich_commands:evaluate",
            "robostrich-layouts = robostrich_commands:layouts",
            "robostrich-stabilize = robostrich_commands:stabilize",
            "robostrich-gap = robostrich_commands:gap",
            "robostrich-play = robostrich_commands:play",
            "robostrich-walk = robostrich_commands:walk",
            "robostrich-export-xml = robostrich_commands:export_xml",
            "robostrich-movement = robostrich_commands:movement",
            "robostrich-workspace = robostrich_commands:workspace",
            "robostrich-targets = robostrich_commands:targets",
            "robostrich-gait = robostrich_commands:gait",
            "robostrich-sweep = robostrich_commands:sweep",
            "robostrich-design = robostrich_commands:design",
            "robostrich-robustness = robostrich_commands:robustness",
        ],
    },
)
