"""automan problems, one module per paper or case family."""
