"""SMACH and FlexBE Python files, read with ``ast`` only (never imported or run), and the SMACH writer."""
