"""The paper's FSM formats: its XML and its text notation."""
