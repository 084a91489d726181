"""Campaigns: devices x models x runs, statistics (Table A.7, Delta, beta), Pareto front."""
