"""Evaluation of decomposers on rendered samples, MIT objects and predictions folders."""
