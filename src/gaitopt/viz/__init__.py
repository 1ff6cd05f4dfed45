"""gaitopt.viz"""
