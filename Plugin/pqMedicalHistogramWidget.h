// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   pqMedicalHistogramWidget
 * @brief   A volume's histogram with its isovalues marked; markers drag.
 *
 * A small painted widget shared by the HistoPyramid Isosurface list
 * (pqMedicalIsosurfaceListWidget) and Block LOD Contour's panel
 * (pqBlockLODLevelWidget). It draws:
 *
 * - the bins as bars whose heights are log(1 + count) (a CT's air and soft
 *   tissue bins hold a hundred to five hundred times more points than its
 *   bone's: a linear scale shows two spikes and nothing of the bone);
 * - the data range on the axis below;
 * - one vertical line per isovalue in its surface's colour, outlined so a
 *   white or black surface still shows on either palette; a value outside
 *   the range is drawn as an arrow at that end, hatched.
 *
 * Pressing near a marker (within a few pixels; the nearest wins) and moving
 * drags it: markerMoved() during the drag, markerReleased() once, on release,
 * when the value changed; Escape during a drag, or a press of another button,
 * puts the value back (markerCancelled()). Dragged values are rounded to what
 * a pixel resolves (to integers for integer data), so a drag to the middle of
 * a CT's bone peak gives 400, not 399.82421875.
 *
 * The widget holds no ParaView state: its owner fills it (setHistogram(),
 * setMarkers()) and turns the signals into property changes.
 * gatherHistogram() counts a source's array where the data lives, through
 * vtkSMMedicalIsosurfaceInitializationHelper::GatherHistogram, so the panels
 * work in client/server sessions with the data on the server.
 *
 * Everything is painted with QPainter in logical pixels (antialiased, fonts
 * from the widget), so it is sharp at any device pixel ratio. Tooltips give the
 * bin under the mouse (its values and count) or the marker under it.
 */
#ifndef pqMedicalHistogramWidget_h
#define pqMedicalHistogramWidget_h

#include <QColor>
#include <QString>
#include <QWidget>

#include <vector>

class vtkSMSourceProxy;

class pqMedicalHistogramWidget : public QWidget
{
  Q_OBJECT
  /// The markers' values, comma-separated ("-500,400"): what the GUI test checks.
  Q_PROPERTY(QString markerValues READ markerValues)
  /// Whether a histogram is shown (false: no one-component array to count).
  Q_PROPERTY(bool hasHistogram READ hasHistogram)
  typedef QWidget Superclass;

public:
  explicit pqMedicalHistogramWidget(QWidget* parent = nullptr);
  ~pqMedicalHistogramWidget() override;

  /// Counts `source`'s point array on output `port` (the active scalars for
  /// an empty name) and shows it; without such an array the widget says so.
  void gatherHistogram(vtkSMSourceProxy* source, unsigned int port, const char* arrayName);

  /// The bins to draw: the first at [low, low + width), one count each, over
  /// the data range `range`. `integral`: dragged values are rounded to integers.
  void setHistogram(const double range[2], double low, double width,
    const std::vector<double>& counts, bool integral);
  /// Forgets the histogram (the widget says there is nothing to show).
  void clearHistogram();
  bool hasHistogram() const { return !this->Counts.empty(); }

  /// The markers: one value each, in these colours (missing colours: the
  /// palette's text colour). Ignored during a drag for the marker dragged,
  /// whose value is the mouse's until release.
  void setMarkers(const std::vector<double>& values, const std::vector<QColor>& colors);
  QString markerValues() const;

  /// The marker being dragged, -1 when none.
  int draggedMarker() const { return this->Dragged; }

  /// The value under x (logical pixels), rounded as a drag rounds it.
  double valueAt(int x) const;
  /// The x (logical pixels) at which a value is drawn.
  double xOf(double value) const;

  QSize sizeHint() const override;
  QSize minimumSizeHint() const override;

Q_SIGNALS:
  /// A marker moves under the mouse (many times a drag).
  void markerMoved(int index, double value);
  /// A drag ends with the marker at `value` (once a drag, only when it moved).
  void markerReleased(int index, double value);
  /// A drag was abandoned: the marker is back at `value`.
  void markerCancelled(int index, double value);

protected:
  void paintEvent(QPaintEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;
  bool event(QEvent* event) override;

private:
  Q_DISABLE_COPY(pqMedicalHistogramWidget)

  /// The plot's rectangle (logical pixels): the widget less the axis labels.
  QRectF plotRect() const;
  /// The marker within grabbing distance of x, nearest first; -1 when none.
  int markerNear(double x) const;
  void cancelDrag();

  double Range[2] = { 0.0, 1.0 };
  double Low = 0.0;
  double Width = 1.0;
  bool Integral = false;
  std::vector<double> Counts;
  std::vector<double> Values;
  std::vector<QColor> Colors;
  int Dragged = -1;
  double DragStart = 0.0;
  bool DragMoved = false;
};

#endif
