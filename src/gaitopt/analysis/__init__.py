"""gaitopt.analysis"""
