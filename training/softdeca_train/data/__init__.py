"""Training data: planning, simulating, storing, streaming and reporting the dataset
of paper sections 3.4 and 3.6.2. Entry points: `python -m softdeca_train generate`,
`report-data`, `bench-datagen`; `loader.ShardDataset` for training. See docs/datagen.md."""
