"""The PDF screening report: figures and pages."""
