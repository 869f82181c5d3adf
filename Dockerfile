# fenics-contact on the official FEniCSx image of the DOLFINx version that
# pyproject.toml pins (>=0.11,<0.12). DOLFINx comes from the image, so the
# package is installed with every extra except `dolfinx` (the wheel).
#
#   docker build -t fenics-contact .
#   docker run --rm -v "$PWD/results:/app/results" fenics-contact          # main demo
#   docker run --rm -v "$PWD/results:/app/results" fenics-contact \
#       fenics-contact run scenes/hertz_cylinder.toml --out results/hertz
ARG DOLFINX_IMAGE=ghcr.io/fenics/dolfinx/dolfinx:v0.11.0
FROM ${DOLFINX_IMAGE}

# Shared libraries the gmsh and VTK wheels load (off-screen rendering via EGL).
RUN apt-get update \
    && apt-get install -y --no-install-recommends \
       libglu1-mesa libxrender1 libxcursor1 libxft2 libxinerama1 libgl1 libegl1 \
    && rm -rf /var/lib/apt/lists/*

WORKDIR /app
COPY . /app
ENV PIP_BREAK_SYSTEM_PACKAGES=1 \
    PYVISTA_OFF_SCREEN=true \
    MPLBACKEND=Agg
RUN python3 -m pip install --no-cache-dir -e ".[mesh,viz,test]"

# Compile the shipped scenes' forms into the image's form cache (~/.cache/fenics),
# so that their first run in a container starts at once (6 minutes for all
# of them on 2 cores). `docker build --build-arg COMPILE_SCENES=0` skips it.
ARG COMPILE_SCENES=1
RUN if [ "$COMPILE_SCENES" = "1" ]; then fenics-contact compile scenes/*.toml; fi

CMD ["python3", "demos/paper_example2.py", "--out", "results/paper-ex2"]
