"""gaitopt.dynamics"""
