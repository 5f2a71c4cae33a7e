"""Peer agents (SBX) on the arm beside ours: the agents, the benchmark's jobs and its record."""
