"""gaitopt.ocp"""
