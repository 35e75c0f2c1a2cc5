"""What people look at: figures, the HTML report, and how runs show in a notebook."""
