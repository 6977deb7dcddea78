"""ngdual: dual-dual mixed finite elements (PEERS) for frictional contact in 2D elasticity.

The data flow is one way: scene -> mesh -> spaces -> forms -> solver -> post.
"""

__version__ = "0.1.0"
