"""sphgen: SPH equations in restricted Python, compiled per scene."""
