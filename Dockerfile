# bearing-twin service image: `docker build -t bearing-twin .` then
#   docker run --rm -p 8000:8000 -p 7447:7447 -v "$PWD/recordings:/home/twin/recordings" bearing-twin
# The package is installed as README's command does, without -e (`pip install -c constraints.txt .`, into a venv):
# the tested versions, without the load tools' httpx; the numba kernels
# are compiled at build time into a cache the runtime user owns, so the first twin starts at once.
FROM python:3.11-slim

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    VIRTUAL_ENV=/opt/venv \
    PATH=/opt/venv/bin:$PATH \
    NUMBA_CACHE_DIR=/home/twin/.cache/numba

# inside a container the service listens on every interface to be reachable (publish the ports
# with -p); outside Docker it binds 127.0.0.1 unless told otherwise
ENV BEARING_TWIN_ZENOH_LISTEN=tcp/0.0.0.0:7447

RUN useradd --create-home --uid 10001 --shell /usr/sbin/nologin twin

WORKDIR /opt/bearing-twin
COPY pyproject.toml README.md constraints.txt ./
COPY twin ./twin
COPY service ./service
RUN python3 -m venv /opt/venv && /opt/venv/bin/pip install -c constraints.txt .

USER twin
WORKDIR /home/twin
COPY --chown=twin:twin scenarios ./scenarios
# compile the numba cache (as the runtime user, into NUMBA_CACHE_DIR) and create recordings/
RUN mkdir -p recordings "$NUMBA_CACHE_DIR" && bearing-twin simulate --duration 0.001 > /dev/null

EXPOSE 8000 7447

HEALTHCHECK --interval=15s --timeout=5s --start-period=60s --retries=3 \
    CMD python -c "import os, sys, urllib.request; port = os.environ.get('BEARING_TWIN_PORT', '8000'); sys.exit(0 if urllib.request.urlopen(f'http://127.0.0.1:{port}/health', timeout=4).status == 200 else 1)"

CMD ["bearing-twin", "serve", "--host", "0.0.0.0"]
