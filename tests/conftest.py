"""Test-wide settings: hypothesis runs derandomised so every run sees the same examples."""

from hypothesis import HealthCheck, settings

settings.register_profile(
    "seawatch",
    derandomize=True,
    deadline=None,
    max_examples=60,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile("seawatch")
