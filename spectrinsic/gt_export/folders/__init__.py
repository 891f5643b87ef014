"""Output folders a verb writes into: the folder rule, the lock and staged output."""
