# Trackstar: REST API (8000) and browser studio (8080) in one process.
#   docker build -t trackstar .
#   docker run -p 127.0.0.1:8000:8000 -p 127.0.0.1:8080:8080 -v trackstar:/data trackstar
# It listens on 0.0.0.0 in the container, so it generates a token at each start and prints it with
# the studio's sign-in URL (docker logs). For a shared server pass the names users type and a
# token of your choice (docs/server.md, "A shared server"):
#   -e TRACKSTAR_ALLOWED_HOSTS=lab-pc.example.edu -e TRACKSTAR_TOKEN=…
FROM python:3.11-slim

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    TRACKSTAR_DATA_DIR=/data \
    NUMBA_CACHE_DIR=/home/trackstar/numba-cache

RUN useradd --create-home --uid 10001 trackstar && mkdir -p /data && chown trackstar /data
WORKDIR /opt/trackstar
COPY pyproject.toml README.md ./
COPY app ./app
COPY planner ./planner
COPY tracks ./tracks
COPY static ./static
COPY examples ./examples
# Editable, so the app finds static/ beside it.
RUN pip install -e .

USER trackstar
# Compile the planner's kernels into numba's cache now: the container starts in seconds.
RUN python -c "from planner.rrt import warm_up; warm_up()"
VOLUME ["/data"]
EXPOSE 8000 8080
HEALTHCHECK --interval=30s --timeout=5s --start-period=60s --retries=3 \
    CMD python -c "import os, urllib.request; urllib.request.urlopen('http://127.0.0.1:%s/health' % os.environ.get('TRACKSTAR_PORT', '8000'), timeout=4)"
CMD ["trackstar", "serve", "--host", "0.0.0.0"]
