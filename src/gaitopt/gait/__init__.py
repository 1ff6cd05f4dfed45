"""gaitopt.gait"""
