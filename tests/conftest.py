"""Shared fixtures. Physics tests cite the seed equation, table or figure they reproduce."""
